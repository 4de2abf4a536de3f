// freefloat.dynamics._sim's robot loop as one translation unit (a unity build): its bindings and
// loop (sim_module.cpp) with the closed plant and the two-hand law (closures.cpp), so that the
// compiler analyses Pinocchio's and Eigen's headers, and the templates both use, once. setup.py
// compiles it at -O1: the loop's time is in libpinocchio_default's algorithms, and -O1 ran every
// scene measured as fast as -O3 (docs/bench.md, "The build").
#include "sim_module.cpp"
#include "closures.cpp"
