// The CVODE reference (reference.hpp), its stepper and runner glue, compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/methods.hpp"
#include "nhi/methods/reference/reference_body.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::ReferenceStepper<nhi::S>; template struct nhi::MethodRun<nhi::ReferenceMethod, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
