// The stepper instances the library compiles once for every registered system
// (lib/src/system_slot.cpp defines them with NHI_STEPPER_INSTANCES(, S)).
// Every body header includes this file, so that code which includes a body
// header to step a system of its own still links to the library's instances
// for the registered systems instead of compiling them again (explicit
// instantiation declarations, `extern template`).
#pragma once

#include "nhi/discrete_gradient.hpp"
#include "nhi/discretization.hpp"
#include "nhi/dla.hpp"
#include "nhi/mp06.hpp"
#include "nhi/reference.hpp"
#include "nhi/spark.hpp"
#include "nhi/systems/registry.hpp"

// PREFIX template class X<S>; for every stepper the library compiles for S
// (PREFIX: extern for the declarations, empty for the definitions).
#define NHI_STEPPER_INSTANCES(PREFIX, S)                                  \
  PREFIX template class nhi::DlaStepper<S, nhi::AlphaDiscretization>;     \
  PREFIX template class nhi::DlaStepper<S, nhi::SymmetricDiscretization>; \
  PREFIX template class nhi::DlaStepper<S, nhi::SplitDiscretization>;     \
  PREFIX template class nhi::Mp06Stepper<S, true>;                        \
  PREFIX template class nhi::Mp06Stepper<S, false>;                       \
  PREFIX template class nhi::DiscreteGradientStepper<S>;                  \
  PREFIX template class nhi::SparkStepper<S, 2>;                          \
  PREFIX template class nhi::SparkStepper<S, 3>;                          \
  PREFIX template class nhi::SparkStepper<S, 4>;                          \
  PREFIX template class nhi::ReferenceStepper<S>;

#define NHI_EXTERN_STEPPER_INSTANCES_(S) NHI_STEPPER_INSTANCES(extern, nhi::S)
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_STEPPER_INSTANCES_)
#undef NHI_EXTERN_STEPPER_INSTANCES_
