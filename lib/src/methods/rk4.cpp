// RK4 on the index-reduced equations (rk4.hpp), compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/methods.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template struct nhi::MethodRun<nhi::Rk4Method, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
