// The solver options a method's spec asks for: the scene's words ("start":
// "continuation") turned into the solver's switches, so that the solver
// (solver.hpp) knows nothing of scenes.
#pragma once

#include "nhi/methods/method_spec.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

// Tolerance and root following (SolverOptions) from the spec.
inline SolverOptions solver_options(const MethodSpec& spec) {
  SolverOptions opt;
  opt.tolerance = spec.tolerance;
  opt.continuation = spec.start == "continuation";
  opt.root_check = spec.root_check && !opt.continuation;
  return opt;
}

}  // namespace nhi
