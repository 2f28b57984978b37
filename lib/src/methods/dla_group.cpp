// The DLA in Remark 4.2's varying chart (methods/group/dla_group.hpp), compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods/group/dla_group_body.hpp"
#include "nhi/methods/methods.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::GroupDlaStepper<nhi::S>; template struct nhi::MethodRun<nhi::GroupDlaMethod, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
