// The DLA's predictor (DlaStepper, dla.hpp): fixed-point passes of eq. (6)
// that refine the stepper's extrapolated start of a step, and polish(), the
// correction of a guess the residual check accepted.  It is a guess only:
// Newton, or the residual check, judges what it returns (NewtonSolver::solve).
//
// A pass freezes the nodes q_c and the velocity inside dL/dq at the current
// guess and solves
//     sum_c w_c dL/dqdot(q_c, v) = p_{k+1} - omega(q_{k+1})^T lambda
//                                  + h sum_c w_c (1 - c) dL/dq(q_c, v_guess)   (eq. 6, first line)
// for v with V(q_cbar, .) (hamiltonian.hpp; exact for a constant mass matrix;
// cbar = sum_c w_c c), q_next = q_{k+1} + h v.  On a separable system with no
// holonomic constraint (kSolvesMultipliers) it first takes the multipliers
// from eq. (6), second line, with the constraint nodes frozen too: V is
// linear in p, so
//     Omega V(q_cbar, rhs - W^T lambda) = 0,  Omega = sum_c w_c omega(q_c),
// is m linear equations in lambda (rhs: the right side above without the
// force).  A pass moves the guess by O(h) times the guess's error, so each one
// gains an order of h (tests/test_dla.cpp).  A pass that moves no coordinate
// by more than 4 eps of its size is a fixed point of eq. (6): *settled says
// so, and the solve then starts with the residual check.  A non-finite pass
// keeps the guess before it.  Three kinds of pass, by what the potential
// allows (chosen at construction): the plain pass above (with a Gauss-Seidel
// first pass where the constraint force misses what omega reads), the pass
// through P = (M - h^2 kappa K)^-1 (a quadratic potential), and the Newton
// pass (a potential of one coordinate); each is explained at its code.
//
// State, all of it updated by the non-const members: the curvature P for the
// last two step sizes, force_forms(q_{k+1})^T of the last refine() (which the
// step's solve also uses), and the last pass's matrices for polish().
// Bodies in dla_predictor_body.hpp.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <tuple>
#include <utility>

#include "nhi/roles/discretization.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/roles/system.hpp"

namespace nhi {

// omega at the constraint nodes of the last evaluations, keyed by the
// coordinates omega reads (omega_reads, hamiltonian.hpp): a node whose read
// coordinates are the same bits gets the same omega without evaluating it.
// On the robot theta is exact after the predictor's first pass, so its
// sincos is taken once or twice a step instead of at every pass and
// residual.
template <class S, int kNodes>
struct OmegaMemo {
  static constexpr int n = S::n, m = S::m;
  std::array<bool, n> reads;
  std::array<Vec<double, n>, kNodes> q;
  std::array<Mat<double, m, n>, kNodes> W;
  std::array<bool, kNodes> valid{};
  explicit OmegaMemo(const S& sys)
      : reads(omega_reads(sys)) {  // (q, W zero: a memo copies cleanly before its first use)
    for (auto& x : q) x.setZero();
    for (auto& w : W) w.setZero();
  }
  const Mat<double, m, n>& at(const S& sys, int k, const Vec<double, n>& qc) {
    bool same = valid[k];
    for (int j = 0; j < n && same; ++j)
      if (reads[j] && !(qc[j] == q[k][j])) same = false;
    if (!same) {
      q[k] = qc;
      W[k] = sys.template omega<double>(qc);
      valid[k] = true;
    }
    return W[k];
  }
};

// The memo for the constraint nodes of the discretization D.
template <class S, class D>
using DlaOmegaMemo = OmegaMemo<S, std::tuple_size<decltype(std::declval<const D&>().constraint_nodes())>::value>;

// dL/dq at (q, v) and its derivative in coordinate r, by one Jet evaluation
// of the partials with one derivative (the Newton passes).
template <class S>
void partials_and_curvature(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& v, int r,
                            Vec<double, S::n>* Lq, Vec<double, S::n>* dLq) {
  constexpr int n = S::n;
  using J = ceres::Jet<double, 1>;
  Vec<J, n> qj, vj, Lqj, Lvj;
  for (int i = 0; i < n; ++i) {
    qj[i] = J(q[i]);
    vj[i] = J(v[i]);
  }
  qj[r].v[0] = 1.0;
  lagrangian_partials(sys, qj, vj, &Lqj, &Lvj);
  for (int i = 0; i < n; ++i) {
    (*Lq)[i] = Lqj[i].a;
    (*dLq)[i] = Lqj[i].v[0];
  }
}

template <class S, class D>
class DlaPredictor {
 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int mc = m + holonomic_count<S>::value;  // multipliers (mu, lambda), as DlaStepProblem's
  using VecN = Vec<double, n>;
  using VecM = Vec<double, mc>;
  using Memo = DlaOmegaMemo<S, D>;
  // Do the passes solve for the multipliers too?  Needs V linear in p (a
  // separable system) and no holonomic constraint (then mc = m).
  static constexpr bool kSolvesMultipliers = holonomic_count<S>::value == 0 && is_separable<S>::value;

  // Passes a step makes (passes()).  A pass is a short chain of dependent
  // operations, cheap in instructions but not in latency, so passes pay only
  // where they end in a guess the residual check accepts (no Jet evaluation
  // and no iteration).
  static constexpr int kMaxPasses = 4, kMinPasses = 2;
  // Newton passes converge quadratically: from the extrapolation the third is
  // at round-off and the residual check confirms it (a fourth would cost more).
  static constexpr int kNewtonPasses = 3, kMaxNewtonPasses = 5;
  static constexpr double kSqrtEps = 1.4901161193847656e-08;  // 2^-26
  static constexpr double kSettled = 4 * std::numeric_limits<double>::epsilon();

  DlaPredictor(const S& sys, const D& disc);

  // Do the passes see the potential exactly: at the known point only (kappa
  // = 0, no interior node), or through P (a quadratic potential)?  Then,
  // where the constraint rows read only coordinates the constraint force does
  // not move, they settle (tests/test_dla.cpp).
  bool exact_in_potential() const { return kSolvesMultipliers && (kappa_ == 0 || affine_potential_force_); }
  // Do the passes take the curvature of a potential of one coordinate at
  // every pass, so that they converge quadratically (Newton passes)?
  bool newton_in_potential() const { return curvature_coordinate_ >= 0; }
  // Is the first pass (Gauss-Seidel) exact: kappa = 0 and the constraint rows
  // read only coordinates the constraint force does not move?
  bool first_pass_exact() const { return gs_; }
  // Do the passes settle from any start of the multipliers (the constraint
  // force leaves alone what omega reads: constraint_force_misses_omega)?
  bool settle_from_any_start() const { return passes_settle_; }

  // The passes of a step, from whether the residual check accepted the last
  // step's guess and the steps made: Newton passes make kNewtonPasses;
  // after an accepted guess the others make kMinPasses (one where the first
  // pass is exact: the check, not a second pass, confirms it); otherwise
  // kMinPasses, or kMaxPasses on every 8th step to find out, and the step is
  // checked only if a pass moved nothing.
  int passes(bool accepted_last, long steps) const {
    return curvature_coordinate_ >= 0         ? kNewtonPasses
           : gs_ && accepted_last             ? 1
           : accepted_last || steps % 8 != 0 ? kMinPasses
                                              : kMaxPasses;
  }

  // Up to `passes` passes of eq. (6) for the step of size h from the newest
  // point (q, p) = (q_{k+1}, p_{k+1}), from (*q_guess, *lambda_guess), which get
  // the result.  *settled (may be null) is set when a pass moved nothing.
  // memo: omega at the constraint nodes (shared with the step's residual).
  // extend: Newton passes may add passes, up to kMaxNewtonPasses, while the
  // last one moved by more than sqrt(eps) of the state's size (at h = 0.4
  // three are often not enough).
  // (Inlined into the stepper's step, as the passes were before they were a
  // class of their own: a call here is on every step's path.)
  [[gnu::always_inline]] inline void refine(const S& sys, const D& disc, double h, const VecN& q, const VecN& p,
                                            int passes, bool extend, Memo* memo, VecN* q_guess, VecM* lambda_guess,
                                            bool* settled);

  // force_forms(q_{k+1})^T, by the last refine() (for the step's solve).
  const Mat<double, n, mc>& Wt() const { return Wt_; }

  // The correction of a guess from the last refine() that the residual check
  // accepted by its second test (NewtonSolver::solve), from its residual r.
  void polish(double h, const Vec<double, n + mc>& r, VecN* q1, VecM* lambda);

 private:
  // The curvature of the passes for one step size: hkK = h^2 kappa K and
  // P = (M - h^2 kappa K)^-1 (ok: P is used).
  struct Curvature {
    Mat<double, n, n> P = Mat<double, n, n>::Zero(), hkK = Mat<double, n, n>::Zero();
    bool ok = false;
  };
  Curvature make_curvature(double h) const;

  // What the passes of one refine() read: the step, the newest point q =
  // q_{k+1} and its p, and P W^T where the passes are curved.
  struct Step {
    const S& sys;
    const D& disc;
    double h, inv_h, cbar;
    const VecN& q;
    const VecN& p;
    bool curved;
    const Mat<double, n, mc>& PWt;
  };
  // What the passes of one refine() take once and reuse: V(q, W^T) (plain
  // and Gauss-Seidel passes), M^-1 W^T and the constrained inverse Pi with
  // the Omega it was taken for (Newton passes).
  struct Reuse {
    Mat<double, n, mc> VWt;
    bool vwt_ready = false;
    Mat<double, n, mc> MWt;
    bool rank_one_started = false;
    Mat<double, n, n> pi;
    Mat<double, mc, n> pi_Om;
    Mat<double, mc, mc> pi_S0;
    bool pi_ready = false;
  };
  // A pass's right side and curvature (pass_sums) and its unknowns.
  struct PassIn {
    VecN vg, rhs, u, qbar;
    int r;
  };

  template <bool kNewton>
  void run_passes(const Step& st, int passes, bool extend, Memo* memo, VecN* q_guess, VecM* lambda_guess,
                  bool* settled);
  template <bool kNewton>
  void pass_sums(const Step& st, const VecN& q_guess, PassIn* in) const;
  template <bool kNewton>
  bool constrained_pass(const Step& st, const PassIn& in, Reuse* reuse, Memo* memo, VecN* q_guess, VecN* q1,
                        VecM* lambda);
  void plain_forms(const Step& st, const VecN& qbar, Reuse* reuse) const;
  void newton_pass(const Step& st, const PassIn& in, const Mat<double, m, n>& Om, Reuse* reuse, VecN* q1,
                   VecM* lambda) const;

  // Set at construction: M^-1 on a separable system, kappa = sum_c w_c c (1 - c),
  // K = d(dL/dq)/dq when constant and not 0, and the kind of pass.
  Mat<double, n, n> Minv_ = Mat<double, n, n>::Zero();
  double kappa_ = 0;
  bool affine_potential_force_ = false;  // dL/dq affine in q (K constant, maybe 0)
  std::optional<Mat<double, n, n>> K_;
  bool passes_settle_ = false;  // constraint_force_misses_omega (separable systems)
  bool gs_ = false;             // passes_settle_ and kappa = 0: the first pass is exact
  // The one coordinate the potential reads when the passes take its curvature (-1: they do not).
  int curvature_coordinate_ = -1;

  StepSizeCache<Curvature> curv_;  // current(): this step's
  Mat<double, n, mc> Wt_ = Mat<double, n, mc>::Zero();
  // The last pass's matrices for polish(): Omega, (Omega G W^T)^-1, and G = P,
  // M^-1 or (I + z e_r^T / (1 - z_r)) M^-1 (W^T: Wt_).
  struct LastPass {
    Mat<double, mc, n> Om = Mat<double, mc, n>::Zero();
    Mat<double, mc, mc> Sinv = Mat<double, mc, mc>::Zero();
    bool curved = false, ok = false;
    bool lazy = false;           // Sinv is still to be taken (a Newton pass)
    VecN z = VecN::Zero();       // z / (1 - z_r) of the last pass, and r (-1: none)
    int zr = -1;
  };
  LastPass last_;
};

}  // namespace nhi
