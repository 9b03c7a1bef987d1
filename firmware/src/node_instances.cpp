// Explicit instantiations of one joint's estimation cycle for both firmware scalars.
#include "jointguard/node/joint_estimator.hpp"

namespace jg {
template Error joint_outward<float>(const JointEstimatorParams<float>&, JointEstimatorState<float>&, float, float,
                                   const OutwardMessage<float>&, OutwardMessage<float>&) noexcept;
template Error joint_outward<q16>(const JointEstimatorParams<q16>&, JointEstimatorState<q16>&, q16, q16,
                                 const OutwardMessage<q16>&, OutwardMessage<q16>&) noexcept;
template Error joint_outward<float>(const JointEstimatorParams<float>&, JointEstimatorState<float>&, float, float, bool,
                                   const OutwardMessage<float>&, OutwardMessage<float>&) noexcept;
template Error joint_outward<q16>(const JointEstimatorParams<q16>&, JointEstimatorState<q16>&, q16, q16, bool,
                                 const OutwardMessage<q16>&, OutwardMessage<q16>&) noexcept;
template bool joint_inward_and_estimate<float>(const JointEstimatorParams<float>&, JointEstimatorState<float>&, float,
                                               float, const InwardMessage<float>&, InwardMessage<float>&,
                                               ObserverInputStatus*) noexcept;
template bool joint_inward_and_estimate<q16>(const JointEstimatorParams<q16>&, JointEstimatorState<q16>&, q16, q16,
                                             const InwardMessage<q16>&, InwardMessage<q16>&, ObserverInputStatus*) noexcept;
template bool joint_inward_and_estimate<float>(const JointEstimatorParams<float>&, JointEstimatorState<float>&, float,
                                               float, bool, const InwardMessage<float>&, InwardMessage<float>&,
                                               ObserverInputStatus*) noexcept;
template bool joint_inward_and_estimate<q16>(const JointEstimatorParams<q16>&, JointEstimatorState<q16>&, q16, q16, bool,
                                             const InwardMessage<q16>&, InwardMessage<q16>&, ObserverInputStatus*) noexcept;
}  // namespace jg

// The node over the loopback port (the MCU backend is bound the same way).
#include "jointguard/hal/loopback_can.hpp"
#include "jointguard/node/joint_node.hpp"

namespace jg {
template class JointNode<float, hal::LoopbackCan<8>>;
template class JointNode<q16, hal::LoopbackCan<8>>;
}  // namespace jg

// The drive (sync pacing, frame routing, status and events) over the loopback port.
#include "jointguard/node/joint_drive.hpp"

namespace jg {
template class JointDrive<float, hal::LoopbackCan<8>>;
template class JointDrive<q16, hal::LoopbackCan<8>>;
}  // namespace jg
