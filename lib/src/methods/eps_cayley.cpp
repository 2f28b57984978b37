// The discrete Euler-Poincare-Suslov step with the Cayley retraction
// (methods/group/eps_cayley.hpp), compiled for every registered system (it
// runs on the Suslov bodies; on the others its constructor throws): this
// method's translation unit (run.hpp).
#include "nhi/methods/group/eps_cayley_body.hpp"
#include "nhi/methods/methods.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::EpsCayleyStepper<nhi::S>; template struct nhi::MethodRun<nhi::EpsCayleyMethod, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
