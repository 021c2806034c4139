// Shadow of every texel of the height map, the GPU half of the shadow twin tests: the hard mask
// (1 = in shadow) by the exact (A1) or the accelerated (A2) traversal or the horizon maps, or the soft lit fraction
// (f32 bits) by branch-and-bound. Rust twins: relume::terrain::relief::shadow_mask and
// relume::terrain::soft::soft_shadow_map.
//! include terrain_shadow.wgsl

struct MaskParams {
    method: u32,          // 0 exact, 1 accelerated, 2 soft (lit fraction), 3 horizon maps
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

@group(0) @binding(0) var<uniform> mask_params: MaskParams;
@group(0) @binding(1) var<storage, read_write> mask: array<u32>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= terrain.width || id.y >= terrain.height) {
        return;
    }
    let i = id.y * terrain.width + id.x;
    if (mask_params.method == 2u) {
        mask[i] = bitcast<u32>(lit_branch_and_bound(i32(id.x), i32(id.y)));
        return;
    }
    var shadowed: bool;
    if (mask_params.method == 3u) {
        shadowed = shadowed_horizon(i32(id.x), i32(id.y));
    } else if (mask_params.method == 1u) {
        shadowed = shadowed_accelerated(i32(id.x), i32(id.y));
    } else {
        shadowed = shadowed_exact(i32(id.x), i32(id.y));
    }
    mask[i] = select(0u, 1u, shadowed);
}
