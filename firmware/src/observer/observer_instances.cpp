// Explicit instantiations of the observer step for both firmware scalars.
#include "jointguard/observer/momentum_observer.hpp"

namespace jg {
template float observer_step<float>(const ObserverCoeffs<float>&, ObserverState<float>&, float, float, float, float,
                                    ObserverInputStatus*) noexcept;
template q16 observer_step<q16>(const ObserverCoeffs<q16>&, ObserverState<q16>&, q16, q16, q16, q16,
                                ObserverInputStatus*) noexcept;
}  // namespace jg
