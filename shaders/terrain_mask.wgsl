// Hard-shadow mask of every texel of the height map (1 = in shadow), by the exact (A1) or the
// accelerated (A2) traversal: the GPU half of the shadow twin tests. Rust twin:
// relume::terrain::relief::shadow_mask.
//! include terrain_shadow.wgsl

struct MaskParams {
    accelerated: u32,
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
    var shadowed: bool;
    if (mask_params.accelerated == 1u) {
        shadowed = shadowed_accelerated(i32(id.x), i32(id.y));
    } else {
        shadowed = shadowed_exact(i32(id.x), i32(id.y));
    }
    mask[id.y * terrain.width + id.x] = select(0u, 1u, shadowed);
}
