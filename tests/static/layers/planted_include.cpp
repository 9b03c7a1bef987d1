// A fixture of the layer tests (tests/static/CMakeLists.txt), never part of a product: a
// file that includes a simulation header. Compiled as a file of io (jg_io's include
// directories) it must not find it, sim being a higher layer; compiled as a file of sim it
// must, which shows the header exists and the first failure is the layer's doing.
#include "sim/simulation.hpp"
