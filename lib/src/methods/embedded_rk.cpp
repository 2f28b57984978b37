// The adaptive pairs rkf78 and dopri5 (embedded_rk.hpp), compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/methods.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template struct nhi::MethodRun<nhi::Rkf78Method, nhi::S>; template struct nhi::MethodRun<nhi::Dopri5Method, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
