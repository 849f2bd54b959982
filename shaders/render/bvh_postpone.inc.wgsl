// Include-only. When the traversal (bvh.inc.wgsl) postpones a lane's triangle tests: by default
// never. The variant facet_render::trace::TraceVariant::postpone swaps this file for
// bvh_postpone_subgroup.inc.wgsl.

// Whether the traversal ever postpones (a constant, so that the default folds every test away).
const BVH_POSTPONES: bool = false;

// What the decision counts against, taken as the traversal begins (here: nothing).
fn bvh_lanes() -> u32 {
    return 0u;
}

// Whether a lane about to test triangles pushes them onto its stack and visits nodes first.
// Called by every lane that has triangles to test, together.
fn bvh_postpone(lanes: u32) -> bool {
    return false;
}
