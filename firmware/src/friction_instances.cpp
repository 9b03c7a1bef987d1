// Explicit instantiations of the friction models for both firmware scalars, so that the
// MCU build compiles (and the nm/size checks inspect) real object code for each.
#include "jointguard/friction/lugre.hpp"
#include "jointguard/friction/stribeck.hpp"

namespace jg {
template float lugre_step<float>(const LuGreDiscrete<float>&, LuGreState<float>&, float) noexcept;
template q16 lugre_step<q16>(const LuGreDiscrete<q16>&, LuGreState<q16>&, q16) noexcept;
template float stribeck_torque<float>(const StribeckParams<float>&, float) noexcept;
template q16 stribeck_torque<q16>(const StribeckParams<q16>&, q16) noexcept;
template float coulomb_viscous_torque<float>(const CoulombViscousParams<float>&, float) noexcept;
template q16 coulomb_viscous_torque<q16>(const CoulombViscousParams<q16>&, q16) noexcept;
}  // namespace jg
