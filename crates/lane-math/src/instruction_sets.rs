//! The instruction sets a kernel can be dispatched to on this processor, for checking that a
//! kernel gives the same bits under each.

use pulp::Arch;

/// Every instruction set this processor can run, as [`pulp::Arch`] values to dispatch with: the
/// widest ([`Arch::new`]), none ([`Arch::Scalar`], one lane), and on x86-64 AVX2 where present
/// (4 lanes). A kernel written over [`Lane`](crate::Lane) does the same operations in the same
/// order under each, its fused multiply-adds rounded once by each ([`Lane::mul_add`](crate::Lane::mul_add)), so it
/// gives the same bits under each; the kernels' tests check it by running under every one of
/// them.
///
/// ```
/// let sets = lane_math::instruction_sets();
/// assert!(sets.len() >= 2);
/// ```
pub fn instruction_sets() -> Vec<Arch> {
    #[allow(unused_mut)]
    let mut sets = vec![Arch::new(), Arch::Scalar];
    #[cfg(target_arch = "x86_64")]
    if let Some(v3) = pulp::x86::V3::try_new() {
        sets.push(Arch::V3(v3));
    }
    sets
}
