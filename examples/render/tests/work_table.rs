//! The render report's work table: vertices per path and wall time per
//! vertex, from a record's counts, for the records that have a count.

use guiding_render::report::{Record, work_table};

fn record(method: &str, spp: u64, vertices: u64, seconds: f64) -> Record {
    Record {
        method: method.into(),
        width: 10,
        height: 5,
        spp,
        vertices,
        seconds,
        ..Record::default()
    }
}

#[test]
fn the_work_table_divides_by_paths_and_by_vertices() {
    // 4 spp x 50 pixels = 200 paths; 500 vertices in 2 ms: 2.5 vertices a
    // path, 4,000 ns a vertex. The second has no count (an old file).
    let t = work_table(&[record("ppg-glt", 4, 500, 2e-3), record("pt-bvh", 4, 0, 1.0)]);
    let rows: Vec<Vec<&str>> = t.lines().map(|l| l.split_whitespace().collect()).collect();
    assert_eq!(rows[0], ["work", "vertices/path", "ns/vertex"]);
    assert_eq!(rows[1], ["ppg-glt", "2.500", "4000.0"]);
    assert_eq!(rows.iter().filter(|r| !r.is_empty()).count(), 2, "{t}");
    assert_eq!(work_table(&[record("pt-bvh", 4, 0, 1.0)]), "");
}
