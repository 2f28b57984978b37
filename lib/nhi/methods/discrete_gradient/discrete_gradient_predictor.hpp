// The discrete gradient's predictor (DiscreteGradientStepper,
// discrete_gradient.hpp): fixed-point passes of the midpoint form's step
// equations, for a separable system (V linear in p, F independent of p).  A
// pass freezes qbar (in F and omega) and Gonzalez's correction c dz at the
// current iterate; the equations are then linear in (p1, lambda) and
// explicit in q1:
//     p1 = p0 - h (Dq - W^T lambda),  Dq = -F(qbar) + c dq,  W = omega(qbar)
//     W (V((p0 + p1)/2) + c dp) = 0   (m equations in lambda: V is linear)
//     q1 = q0 + h (V((p0 + p1)/2) + c dp).
// At a fixed point every frozen quantity has its true value, so it is the
// step's solution.  Each pass shrinks the error by a factor O(h) (measured:
// 0.02-0.05 at h = 0.2, 1e-4 at h = 0.0125, on the paper's scenes and the
// oscillators).  Where F is affine in q the passes are exact in the force
// (curved passes, with a Gauss-Seidel first pass where the constraint force
// misses what omega reads); slow passes are mixed (Anderson mixing).  Each is
// explained at its code.
//
// State, updated by the non-const members: Q = (I - (h^2/4) K M^-1)^-1 for
// the last two step sizes, and counts of the passes made.  Bodies in
// discrete_gradient_predictor_body.hpp.
#pragma once

#include <array>
#include <limits>
#include <optional>

#include "nhi/roles/hamiltonian.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

template <class S>
struct DiscreteGradientProblem;  // discrete_gradient.hpp

template <class S>
class DiscreteGradientPredictor {
 public:
  static constexpr int n = S::n, m = S::m, ny = 2 * n + m;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, m>;
  using VecY = Vec<double, ny>;  // (q1, p1, lambda)
  using Problem = DiscreteGradientProblem<S>;

  // What the constants bound: at passes().
  static constexpr int kPasses = 12, kPredict = 3;
  static constexpr double kSettled = 4 * std::numeric_limits<double>::epsilon();
  static constexpr double kStall = 1e-10;
  static constexpr double kMaxGamma = 4;

  explicit DiscreteGradientPredictor(const S& sys);  // (reads sys; keeps none of it)

  // Do the passes see the force exactly (F affine in q)?
  bool exact_in_force() const { return affine_force_; }
  // Passes made since construction, those after a Gauss-Seidel first pass included.
  long passes_made() const { return passes_made_; }
  // Did the last passes() end on a plain pass settled by its move?
  bool settled_by_move() const { return settled_by_move_; }

  // Is the first pass at step size h exact whatever its input (a quadratic
  // H, passes exact in the force, and a Gauss-Seidel first pass)?  Then the
  // passes may start from z1 = z0.
  bool first_pass_exact(double h);

  // Fixed-point passes of the step's equations from *y = (q1, p1, lambda),
  // which gets their iterate; true when they settle (the solve then starts
  // with the residual check).  A separable system only.
  bool passes(const Problem& prob, VecY* y);

 private:
  // Q and M^-1 Q for one step size (ok: the passes are curved), and whether
  // the Gauss-Seidel first pass is exact (make_curvature).
  struct Curvature {
    Mat<double, n, n> Q = Mat<double, n, n>::Zero(), MQ = Mat<double, n, n>::Zero();
    bool ok = false;
    bool first_pass_exact = false;
  };
  const Curvature& curvature(double h);
  Curvature make_curvature(double h) const;

  // One pass's output, its move and the bounds of its settling test.
  struct PassOut {
    VecN q1, p1, bound_q, bound_p;
    VecM l;
    double move = 0;
    bool exact = false;  // a Gauss-Seidel first pass
    bool fixed = false;
  };
  // Anderson mixing's memory: the last output g and its move f = g - x, and
  // the pass from which the passes are mixed (-1: not).
  struct Mixing {
    Vec<double, 2 * n> f_prev, g_prev;
    int from = -1;
  };

  bool run(const Problem& prob, VecY* y, bool allow_curved);
  // (Inlined into run(): as a call per pass it cost the contact oscillator's
  // step 5 %, bench_steps.)
  [[gnu::always_inline]] inline bool pass(const Problem& prob, const VecN& q1, const VecN& p1, bool curved, int pass,
                                          PassOut* out);
  void curved_pass(const Problem& prob, const VecN& q1, const VecN& Dq, const VecN& cp, const VecN& qb, int pass,
                   Mat<double, m, n>* W, PassOut* out) const;
  void plain_pass(const Problem& prob, const VecN& Dq, const VecN& cp, const VecN& qb, const Mat<double, m, n>& W,
                  PassOut* out) const;
  bool mix_or_give_up(const PassOut& out, const VecN& q1, const VecN& p1, int pass, double last_move, double size,
                      int* mix_from) const;
  void next_input(const PassOut& out, int pass, Mixing* mix, VecN* q1, VecN* p1) const;
  bool misses_omega(const Mat<double, n, m>& moved) const;

  // F affine in q: K = dF/dq (when not 0) and M^-1.
  bool affine_force_ = false;
  std::optional<Mat<double, n, n>> K_;
  Mat<double, n, n> Minv_ = Mat<double, n, n>::Zero();
  // The Gauss-Seidel first pass: constraint_force_misses_omega, and omega_reads.
  bool gs_ = false;
  std::array<bool, n> omega_reads_{};
  StepSizeCache<Curvature> curv_;  // current(): this step's
  long passes_made_ = 0;
  bool settled_by_move_ = false;
};

}  // namespace nhi
