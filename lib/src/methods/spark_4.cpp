// SPARK's 4-stage stepper (spark.hpp), compiled for every registered system.
#include "nhi/methods/spark/spark_body.hpp"
#include "nhi/systems/registry.hpp"

#define NHI_INSTANCES_(S) template class nhi::SparkStepper<nhi::S, 4>;
NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
