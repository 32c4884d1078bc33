//! A snapshot's arrays end to end in one word buffer, so the kernel binds
//! one storage buffer for all of them (WebGPU guarantees only eight per
//! shader stage).

use guiding::snapshot::Snapshot;

/// A snapshot as one word buffer: the first sixteen words give each
/// array's word offset (spatial nodes, cells, cut nodes, fractions,
/// visibilities, tree pairs, first-right positions, bounds, leaf
/// positions, header: the WGSL constants `SPATIAL` .. `HEADER`); the
/// arrays follow, each as its `bytemuck` words, then one spare word so
/// that no offset points past the end.
#[derive(Clone, Debug, PartialEq)]
pub struct Packed {
    /// The words to upload.
    pub words: Vec<u32>,
}

/// Packs `snapshot`'s arrays (see [`Packed`]).
pub fn pack(snapshot: &Snapshot) -> Packed {
    let a = snapshot.arrays();
    let header: &[u32; 16] = bytemuck::cast_ref(a.header);
    let parts: [&[u32]; 10] = [
        a.spatial,
        bytemuck::cast_slice(a.cells),
        bytemuck::cast_slice(a.cut_nodes),
        bytemuck::cast_slice(a.fractions),
        bytemuck::cast_slice(a.visibility),
        bytemuck::cast_slice(a.tree),
        a.first_right,
        bytemuck::cast_slice(a.bounds),
        a.leaf_position,
        header,
    ];
    let mut words = vec![0u32; 16];
    for (i, part) in parts.iter().enumerate() {
        words[i] = words.len() as u32;
        words.extend_from_slice(part);
    }
    words.push(0);
    Packed { words }
}
