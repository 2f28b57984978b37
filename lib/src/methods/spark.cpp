// SPARK (spark.hpp): its runner glue and its two-stage stepper, compiled for
// every registered system (spark_3.cpp, spark_4.cpp: the other stage counts,
// apart so that the cores compile them side by side).
#include "nhi/methods/methods.hpp"
#include "nhi/methods/spark/spark_body.hpp"
#include "nhi/runner/run_body.hpp"
#include "nhi/systems/registry.hpp"

// clang-format off
#define NHI_INSTANCES_(S) template class nhi::SparkStepper<nhi::S, 2>; template struct nhi::MethodRun<nhi::SparkMethod, nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
