// DlaStepper with L_d^{sym,alpha}, omega_d^{sym,alpha} (eqs. 10, 14), compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::DlaStepper<nhi::S, nhi::SymmetricDiscretization>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
