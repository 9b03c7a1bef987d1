// Explicit instantiations of one joint's recursion steps for both firmware scalars.
#include "jointguard/dynamics/momentum_recursion.hpp"

namespace jg {
template void outward_step<float>(const LinkConstants<float>&, float, float, const OutwardMessage<float>&,
                                  OutwardState<float>&, OutwardMessage<float>&) noexcept;
template void outward_step<q16>(const LinkConstants<q16>&, q16, q16, const OutwardMessage<q16>&, OutwardState<q16>&,
                                OutwardMessage<q16>&) noexcept;
template void inward_step<float>(const LinkConstants<float>&, float, const OutwardState<float>&,
                                 const InwardMessage<float>&, InwardMessage<float>&, JointMomentum<float>&) noexcept;
template void inward_step<q16>(const LinkConstants<q16>&, q16, const OutwardState<q16>&, const InwardMessage<q16>&,
                               InwardMessage<q16>&, JointMomentum<q16>&) noexcept;
}  // namespace jg
