// Explicit instantiations of the detector for both firmware scalars (MCU object checks).
#include "jointguard/detection/detector.hpp"

namespace jg {
template bool detector_step<float>(const JointThreshold<float>&, DebounceSettings, JointDetectorState&, float,
                                   float) noexcept;
template bool detector_step<q16>(const JointThreshold<q16>&, DebounceSettings, JointDetectorState&, q16, q16) noexcept;
}  // namespace jg
