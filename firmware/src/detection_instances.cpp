// Explicit instantiations of the detector for both firmware scalars (MCU object checks).
#include "jointguard/detection/detector.hpp"
#include "jointguard/detection/hold_detector.hpp"
#include "jointguard/detection/residual_detector.hpp"

namespace jg {
template bool detector_step<float>(const JointThreshold<float>&, DebounceSettings, JointDetectorState&, float, float,
                                   bool) noexcept;
template bool detector_step<q16>(const JointThreshold<q16>&, DebounceSettings, JointDetectorState&, q16, q16,
                                 bool) noexcept;
template bool hold_change_step<float>(const HoldChangeParams<float>&, HoldChangeState<float>&, bool, float) noexcept;
template bool hold_change_step<q16>(const HoldChangeParams<q16>&, HoldChangeState<q16>&, bool, q16) noexcept;
template bool residual_change_step<float>(const ResidualChangeParams<float>&, ResidualChangeState<float>&, float) noexcept;
template bool residual_change_step<q16>(const ResidualChangeParams<q16>&, ResidualChangeState<q16>&, q16) noexcept;
}  // namespace jg
