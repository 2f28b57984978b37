// Every stepper, usable on any system of one's own: the light headers and
// every body header (the heavy member definitions that the library compiles
// only for its registered systems), the method list and the integrate loop.
// Include this one header in code that steps a system the registry does not
// have (README "Your own system"); code that steps only registered systems
// may include the light headers and link to the library's instances instead.
#pragma once

#include "nhi/methods/composition.hpp"
#include "nhi/methods/discrete_gradient/discrete_gradient_body.hpp"
#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/methods/dla/dla_composition.hpp"
#include "nhi/methods/explicit/embedded_rk.hpp"
#include "nhi/methods/explicit/rk4.hpp"
#include "nhi/methods/group/dla_group_body.hpp"
#include "nhi/methods/methods.hpp"
#include "nhi/methods/mp06/mp06_body.hpp"
#include "nhi/methods/reference/reference_body.hpp"
#include "nhi/methods/spark/spark_body.hpp"
#include "nhi/roles/guard.hpp"
#include "nhi/roles/integrate.hpp"
#include "nhi/roles/observer.hpp"
#include "nhi/roles/system.hpp"
