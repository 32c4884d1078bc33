//! One front shape: the GLT and the field each locate a path vertex once
//! (`vertex(&ctx)`), and the light vertex it gives records and counts
//! exactly as documented, whichever structure holds it.

mod common;

use common::{LightsAt, scene, two_rooms};
use glam::Vec3;
use guiding::cut::CutConfig;
use guiding::field::{FieldConfig, GuidingField};
use guiding::glt::{Glt, GltConfig};
use guiding::light_tree::BuildHeuristic;
use guiding::{DroppedRecords, LightId, LightTree, RecordOutcome, ShadingContext};

/// Records made through one vertex, `(light, value, unshadowed)`, with the
/// outcome of the light record and of the visibility record
/// `(min(value, unshadowed), unshadowed)` each must give.
fn mixed_records(n: u32) -> [(LightId, f32, f32, RecordOutcome, RecordOutcome); 7] {
    use RecordOutcome::{Dropped, Recorded, Zero};
    [
        (LightId::Emitter(3), 1.0, 2.0, Recorded, Recorded),
        // The visibility record is min(NaN, 2) = 2 of 2: valid.
        (LightId::Emitter(3), f32::NAN, 2.0, Dropped, Recorded),
        (LightId::Emitter(n + 5), 1.0, 2.0, Dropped, Dropped),
        (LightId::Emitter(4), -1.0, 2.0, Dropped, Dropped),
        (LightId::Emitter(4), 0.0, 2.0, Zero, Recorded),
        (LightId::Emitter(5), 3.0, 2.0, Recorded, Recorded),
        // No unbounded light is configured.
        (LightId::Unbounded(0), 1.0, 1.0, Dropped, Dropped),
    ]
}

/// Bad records are dropped and counted, good ones are not, through the
/// vertex of either structure; a vertex at a non-finite point does not
/// exist and counts as a dropped position.
fn drops_and_counts<G: LightsAt>(guide: &G, dropped: impl Fn(&G) -> DroppedRecords, n: u32) {
    let v = guide.light_at(Vec3::new(-3.0, 1.0, 2.0));
    for (k, (light, value, unshadowed, as_light, as_visibility)) in
        mixed_records(n).into_iter().enumerate()
    {
        assert_eq!(v.record_light(light, value), as_light, "record {k}");
        let seen = value.min(unshadowed);
        let got = v.record_visibility(light, seen, unshadowed);
        assert_eq!(got, as_visibility, "record {k}");
    }
    // Four light records and three visibility records were bad.
    assert_eq!(dropped(guide).light, 4 + 3);
    assert_eq!(dropped(guide).total(), 4 + 3);
    assert!(guide.light_vertex(Vec3::new(f32::NAN, 0.0, 0.0)).is_none());
    assert_eq!(dropped(guide).position, 1);
}

fn visibility() -> CutConfig {
    CutConfig {
        visibility: true,
        ..CutConfig::default()
    }
}

#[test]
fn glt_vertices_drop_and_count_bad_records() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = GltConfig {
        cut: visibility(),
        ..GltConfig::default()
    };
    let glt = Glt::new(&tree, scene(), config).unwrap();
    drops_and_counts(&glt, |g| g.dropped_records(), lights.len() as u32);
}

#[test]
fn field_vertices_drop_and_count_bad_records() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let config = FieldConfig {
        cut: visibility(),
        ..FieldConfig::default()
    };
    let field = GuidingField::new(&tree, scene(), config).unwrap();
    drops_and_counts(&field, |f| f.dropped_records(), lights.len() as u32);
    // The field's vertex is one lookup for both parts: the same cell.
    let v = field.vertex(&ShadingContext::at(Vec3::ONE)).unwrap();
    assert_eq!(v.direction.position(), v.light.position());
    assert_eq!(field.locate(Vec3::ONE), Some(v.direction.cell()));
}

/// Without learned visibility a visibility record is checked and ignored:
/// nothing is counted for a good one, a bad one is still dropped.
#[test]
fn visibility_records_without_learning_are_ignored() {
    let lights = two_rooms();
    let tree = LightTree::build(&lights, BuildHeuristic::Sarh).unwrap();
    let glt = Glt::new(&tree, scene(), GltConfig::default()).unwrap();
    let v = glt.light_at(Vec3::ONE);
    let light = LightId::Emitter(2);
    assert_eq!(v.record_visibility(light, 1.0, 2.0), RecordOutcome::Ignored);
    assert_eq!(v.record_visibility(light, 3.0, 2.0), RecordOutcome::Dropped);
    assert_eq!(glt.dropped_records().light, 1);
}
