// Every stepper, usable on any system of one's own: the light headers and
// every body header (the heavy member definitions that the library compiles
// only for its registered systems), the method list and the integrate loop.
// Include this one header in code that steps a system the registry does not
// have (README "Your own system"); code that steps only registered systems
// may include the light headers and link to the library's instances instead.
#pragma once

#include "nhi/composition.hpp"
#include "nhi/discrete_gradient_body.hpp"
#include "nhi/dla_body.hpp"
#include "nhi/dla_composition.hpp"
#include "nhi/embedded_rk.hpp"
#include "nhi/guard.hpp"
#include "nhi/integrate.hpp"
#include "nhi/methods.hpp"
#include "nhi/mp06_body.hpp"
#include "nhi/observer.hpp"
#include "nhi/reference_body.hpp"
#include "nhi/rk4.hpp"
#include "nhi/spark_body.hpp"
#include "nhi/system.hpp"
