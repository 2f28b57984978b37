// mp06 (mp06.hpp), its steppers and runner glue, compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/methods.hpp"
#include "nhi/methods/mp06/mp06_body.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::Mp06Stepper<nhi::S, true>; template class nhi::Mp06Stepper<nhi::S, false>; template struct nhi::MethodRun<nhi::Mp06Method, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
