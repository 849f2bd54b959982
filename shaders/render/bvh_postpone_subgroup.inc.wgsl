// Include-only, in place of bvh_postpone.inc.wgsl (facet_render::trace::TraceVariant::postpone).
// Postponed triangle tests (Ylitie, Karras, Laine 2017, after Aila & Laine 2009's speculative
// traversal): a lane about to test triangles while too few lanes of its subgroup are doing the
// same pushes them and visits nodes, so that the subgroup tests triangles together instead of
// idling beside one lane that does. Too few: under BVH_POSTPONE_BELOW percent of the lanes that
// began the traversal together.
enable subgroups;

override BVH_POSTPONE_BELOW: u32 = 20u;

const BVH_POSTPONES: bool = true;

// Lanes set in a ballot.
fn bvh_ballot_count(b: vec4<u32>) -> u32 {
    return countOneBits(b.x) + countOneBits(b.y) + countOneBits(b.z) + countOneBits(b.w);
}

// The lanes of the subgroup that begin the traversal together.
fn bvh_lanes() -> u32 {
    return bvh_ballot_count(subgroupBallot(true));
}

fn bvh_postpone(lanes: u32) -> bool {
    let ready = bvh_ballot_count(subgroupBallot(true));
    return ready * 100u < BVH_POSTPONE_BELOW * lanes;
}
