// freefloat.dynamics._sim's robot loop as one translation unit (a unity build): the loop and its
// factory (simulation.cpp) with the closed plant and the two-hand law (closures.cpp) and the
// generalized Jacobian (pin_generalized_jacobian.cpp), so that the compiler analyses the templates
// they share once. It includes no Pinocchio header: its Pinocchio calls are sim/pin_plant.hpp's,
// compiled in cpp/pin_plant.cpp; the bindings (sim_module.cpp) and the detumbling solver
// (detumbling.cpp) are units of their own. setup.py compiles it at -O1: the loop's time is in
// libpinocchio_default's algorithms, and -O1 ran every scene measured as fast as -O3
// (docs/bench.md, "The build").
#include "simulation.cpp"
#include "closures.cpp"
#include "pin_generalized_jacobian.cpp"
