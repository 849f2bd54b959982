// Shading stage of measured RGL `.bsdf` materials (facet_render::materials::rgl): f, its sampling and its pdf from the file's
// own warps (render/materials/rgl.inc.wgsl, the twin of facet_fit::sources::rgl::RglBsdf), as Mitsuba 3's
// `measured` plugin evaluates and samples them. The view direction ωo is the file's parameter
// direction (Mitsuba's si.wi); the light or sampled direction ωi is the one it tabulates.

#include "render/frame.inc.wgsl"
#include "render/bvh.inc.wgsl"
#include "render/scene.inc.wgsl"
#include "render/shade.inc.wgsl"
#include "render/materials/rgl.inc.wgsl"

override Q_SHADE: u32;

struct Bsdf {
    table: RglTable,
    // the GGX α the ray cone widens by
    cone_alpha: f32,
}

fn bsdf_setup(s: Surface, slot: u32) -> Bsdf {
    let r = rgl_block(s.material, 0u);
    return Bsdf(rgl_at(r.table), r.cone_alpha);
}

fn bsdf_eval2(b: Bsdf, wi_light: vec3<f32>, wi_bsdf: vec3<f32>, wo: vec3<f32>) -> array<vec3<f32>, 2> {
    return array<vec3<f32>, 2>(rgl_eval(b.table, wo, wi_light), rgl_eval(b.table, wo, wi_bsdf));
}

fn bsdf_pdf(b: Bsdf, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    return rgl_pdf(b.table, wo, wi);
}

fn bsdf_sample_wi(b: Bsdf, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    return rgl_sample(b.table, wo, u.xy);
}

fn bsdf_roughness(b: Bsdf) -> f32 {
    return b.cone_alpha;
}

@compute @workgroup_size(WG)
fn shade_rgl(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let slot = queue_slot(Q_SHADE, thread_index(gid, nwg));
    if (slot == 0xffffffffu) {
        return;
    }
    shade(slot);
}
