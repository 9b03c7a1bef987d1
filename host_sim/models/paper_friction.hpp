// The paper's identified LuGre parameters (Zhang et al., Sensors 2020, 20, 4187, Table 1;
// see ../shared/paper/READING.md section 5). Used as default plant truth and in tests.
#pragma once

#include <array>

#include "jointguard/friction/lugre.hpp"

namespace jg::sim {

inline constexpr std::array<LuGreParams<double>, 3> kPaperTable1 = {{
    {98467.9088, 314.0483, 6.4865, 7.8322, 4.0033, 0.0978},
    {95487.8562, 499.4331, 6.1838, 8.1855, 4.5407, 0.0996},
    {94546.6673, 489.1297, 5.3929, 7.0023, 4.9450, 0.0917},
}};

}  // namespace jg::sim
