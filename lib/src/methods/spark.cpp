// SPARK (spark.hpp), its steppers and runner glue, compiled
// for every registered system: this method's translation unit (run.hpp).
#include "nhi/methods.hpp"
#include "nhi/run_body.hpp"
#include "nhi/spark_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::SparkStepper<nhi::S, 2>; template class nhi::SparkStepper<nhi::S, 3>; template class nhi::SparkStepper<nhi::S, 4>; template struct nhi::MethodRun<nhi::SparkMethod, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
