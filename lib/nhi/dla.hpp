// The discrete Lagrange-d'Alembert (DLA) method (paper eq. 6) in
// position-momentum form.  Given (q_k, p_k) with p_k = D2 L_d(q_{k-1}, q_k),
// solve the n+m equations
//     p_k + D1 L_d(q_k, q_{k+1}) - omega(q_k)^T lambda_k = 0       (eq. 6, first line)
//     omega_d(q_k, q_{k+1})                            = 0       (eq. 6, second line)
// for (q_{k+1}, lambda_k); then p_{k+1} = D2 L_d(q_k, q_{k+1}).
// A system with l holonomic constraints g (system.hpp) gets the Constrained
// Coordinate Formulation (eq. 17) instead: l more multipliers on the rows Dg(q_k)
// and l more equations g(q_{k+1}) = 0; the multiplier vector is (mu, lambda)
// with mu on omega first.
// The Jacobian of the residual is the matrix (7):
//     [ D2 D1 L_d(q_k, q_{k+1})   -omega(q_k)^T ]
//     [ D2 omega_d(q_k, q_{k+1})        0       ]
// so the step is a saddle-point problem for NewtonSolver (solver.hpp) with
// y = q_{k+1} and Wt = omega(q_k)^T: only the equations live here.
//
// Three layers: DlaStepProblem (the residual), DlaMap (the one-step map
// (q_k, p_k) -> (q_{k+1}, p_{k+1}), stateless), DlaStepper (the stateful stepper
// the integrate loop drives, stepper.hpp).
//
// Symmetry: with a self-adjoint discretization (alpha = 1/2, the symmetric
// family) the *position* sequence is reversible: from (q_{k+1}, p_{k+1}) a step
// of -h returns exactly q_k (with multiplier 0), but the momentum comes back as
// p_k - omega(q_k)^T lambda_k, because the constraint force acts at q_k only.
// So the map on T*Q is not self-adjoint; MethodTraits says symmetric_in_phase = false.
#pragma once

#include <array>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>

#include "nhi/discretization.hpp"
#include "nhi/hamiltonian.hpp"
#include "nhi/solver.hpp"
#include "nhi/stepper.hpp"

namespace nhi {

using DlaOptions = SolverOptions;

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

// dL/dq at (q, v) and its derivative in coordinate r, by one Jet evaluation
// of the partials with one derivative (DlaStepper::next_guess).
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

// The residual of eq. (6) / (17) at fixed (q_k, p_k), for NewtonSolver.
template <class S, class D>
struct DlaStepProblem {
  static constexpr int n = S::n;
  static constexpr int m = S::m;                       // nonholonomic constraints omega
  static constexpr int l = holonomic_count<S>::value;  // holonomic constraints g (eq. 17)
  static constexpr int mc = m + l;                     // multipliers (mu, lambda)
  static constexpr int ny = n, nl = mc;
  using VecN = Vec<double, n>;

  const S& sys;
  const D& disc;
  double h;
  const VecN& q_curr;
  const VecN& p_curr;
  Mat<double, n, mc> W_t;  // force_forms(q_k)^T: the multiplier columns

  // Wt (may be null): force_forms(q)^T, if the caller has it (the stepper's predictor).
  DlaStepProblem(const S& s, const D& d, double hh, const VecN& q, const VecN& p,
                 const Mat<double, n, mc>* Wt = nullptr)
      : sys(s), disc(d), h(hh), q_curr(q), p_curr(p), W_t(Wt ? *Wt : force_forms(s, q).transpose()) {}

  // The one-forms the multipliers act on at q_k: omega(q_k) and, with holonomic
  // constraints, Dg(q_k) below it (eq. 17, first line).
  static Mat<double, mc, n> force_forms(const S& sys, const VecN& q) {
    Mat<double, mc, n> W;
    W.template topRows<m>() = sys.template omega<double>(q);
    if constexpr (l > 0) W.template bottomRows<l>() = holonomic_jacobian(sys, q);
    return W;
  }

  const Mat<double, n, mc>& Wt() const { return W_t; }

  // Root following (solver.hpp): the same step at h2 (W_t is omega(q_k)^T,
  // independent of h); as h -> 0 the root tends to q_{k+1} = q_k with
  // multipliers 0 (they carry the factor h, as L_d does).
  DlaStepProblem at_step(double h2) const {
    DlaStepProblem c = *this;
    c.h = h2;
    c.d2_valid_ = false;
    return c;
  }
  void small_step_start(double ratio, VecN* q1, Vec<double, mc>* lambda) const {
    *q1 = q_curr + ratio * (*q1 - q_curr);
    *lambda *= ratio;
  }

  using Memo = OmegaMemo<S, std::tuple_size<decltype(std::declval<const D&>().constraint_nodes())>::value>;
  Memo* memo = nullptr;  // omega at the constraint nodes, for the double residual (may be null)
  // D2 L_d(q_k, q1) at the q1 of the last double residual (d2_at_), for
  // p_{k+1} = D2 L_d(q_k, q_{k+1}) (top of this file) without evaluating the partials again.
  mutable VecN d2_, d2_at_;
  mutable bool d2_valid_ = false;

  // Round-off in (q1 - q0)/h grows with |q_k| + |q_{k+1}| (a coordinate that has travelled far).
  VecN y_scale(const VecN& q1) const { return q_curr.cwiseAbs() + q1.cwiseAbs(); }

  // r = (p_k + D1 L_d(q_k, q1) - W^T lambda, omega_d(q_k, q1) [, g(q1)]);
  // *terms gets, per row, the sum of the magnitudes of the terms r_i adds up.
  template <class T>
  void residual(const Vec<T, n>& q1, const Vec<T, mc>& lambda, Vec<T, n + mc>* r, Vec<double, n + mc>* terms) const {
    const Vec<T, n> q0 = q_curr.template cast<T>();
    Vec<T, n> D1;
    if constexpr (std::is_same_v<T, double>) {
      // D2 L_d(q_k, q1) comes from the same partials at the same nodes: kept
      // for p_{k+1} if q1 is the solution (DlaMap::step).
      discrete_lagrangian_slots<S, D, T>(sys, disc, h, q0, q1, &D1, &d2_);  // eq. 9 / 10
      d2_at_ = q1;
      d2_valid_ = true;
    } else {
      discrete_lagrangian_slots<S, D, T>(sys, disc, h, q0, q1, &D1, nullptr);  // eq. 9 / 10
    }
    Vec<double, m> cscale;
    const auto omega_at = [this](int k, const Vec<T, n>& qc) -> Mat<T, m, n> {
      if constexpr (std::is_same_v<T, double>)
        if (memo) return memo->at(sys, k, qc);
      return sys.template omega<T>(qc);
    };
    const Vec<T, m> wd =
        discrete_constraint_with<S, D, T>(omega_at, disc, h, q0, q1, terms ? &cscale : nullptr);  // eq. 13 / 14
    for (int i = 0; i < n; ++i) {
      T force = cst<T>(0.0);
      for (int a = 0; a < mc; ++a) force += scale(lambda[a], W_t(i, a));
      (*r)[i] = cst<T>(p_curr[i]) + D1[i] - force;  // eq. 6, first line
      if (terms) {
        double fscale = 0;
        for (int a = 0; a < mc; ++a) fscale += std::abs(W_t(i, a) * value_of(lambda[a]));
        (*terms)[i] = std::abs(p_curr[i]) + std::abs(value_of(D1[i])) + fscale;
      }
    }
    for (int a = 0; a < m; ++a) {
      (*r)[n + a] = wd[a];  // eq. 6, second line
      if (terms) (*terms)[n + a] = cscale[a];
    }
    if constexpr (l > 0) {  // g(q_{k+1}) = 0 (eq. 17, second line); its scale comes from Dg
      const Vec<T, l> gv = sys.template g<T>(q1);
      for (int a = 0; a < l; ++a) {
        (*r)[n + m + a] = gv[a];
        if (terms) (*terms)[n + m + a] = 0;
      }
    }
  }
};

// The DLA one-step map (q_k, p_k) -> (q_{k+1}, lambda_k, p_{k+1}) at step h.
template <class S, class D>
class DlaMap {
 public:
  using Problem = DlaStepProblem<S, D>;
  static constexpr int n = S::n, m = S::m, l = Problem::l, mc = Problem::mc, N = n + mc;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, mc>;
  using VecX = Vec<double, N>;

  DlaMap(const S& sys, const D& disc, double h, DlaOptions options = {})
      : sys_(sys), disc_(disc), h_(h), options_(options) {}

  const S& system() const { return sys_; }
  const D& discretization() const { return disc_; }
  double h() const { return h_; }
  void set_h(double h) { h_ = h; }
  const DlaOptions& options() const { return options_; }

  // One DLA step from (q_curr, p_curr).  q_guess and lambda (in) are the
  // starting iterate; on success q_next, lambda and p_next hold the solution.
  // check_guess: the guess may already solve the step, and polish corrects
  // it if it does (NewtonSolver::solve).
  // Wt (may be null): force_forms(q_curr)^T, if the caller has it; memo (may
  // be null): omega at the constraint nodes of earlier evaluations.
  template <class Polish = typename NewtonSolver<Problem>::NoPolish>
  StepSummary step(const VecN& q_curr, const VecN& p_curr, const VecN& q_guess, VecN* q_next, VecM* lambda,
                   VecN* p_next, bool check_guess = false, const Polish& polish = {},
                   const Mat<double, n, mc>* Wt = nullptr, typename Problem::Memo* memo = nullptr) const {
    Problem prob(sys_, disc_, h_, q_curr, p_curr, Wt);
    prob.memo = memo;
    VecN q1 = q_guess;
    StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&q1, lambda, check_guess, polish);
    if (s.status == SolveStatus::kConverged) {
      *q_next = q1;
      // p_{k+1} = D2 L_d(q_k, q_{k+1}): the last residual's when it was taken
      // at this q_{k+1} to the bit (the residual check accepted the guess as
      // it was; the same sums in the same order, so the same p_{k+1} as
      // evaluating it here, which is the fallback).  It saves evaluating the
      // partials at every node again (the robot's cos psi).
      if (prob.d2_valid_ && (prob.d2_at_.array() == q1.array()).all()) {
        *p_next = prob.d2_;
      } else {
        discrete_lagrangian_slots<S, D, double>(sys_, disc_, h_, q_curr, *q_next, nullptr, p_next);
      }
      if (!all_finite(*p_next)) {
        s.status = SolveStatus::kFailed;
        s.failure = FailureKind::kNonFinite;
        s.message = "non-finite momentum p_{k+1}";
      }
    }
    return s;
  }

  // Relative residual of eq. (6) at (q_next, lambda); *r_out gets the residual.
  double relative_residual(const VecN& q_curr, const VecN& p_curr, const VecN& q_next, const VecM& lambda,
                           VecX* r_out = nullptr) const {
    const Problem prob(sys_, disc_, h_, q_curr, p_curr);
    return NewtonSolver<Problem>(prob, options_).relative_residual(q_next, lambda, r_out);
  }

 private:
  S sys_;
  D disc_;
  double h_;
  DlaOptions options_;
};

// The stateful DLA stepper (stepper.hpp).  Start: p_0 = dL/dqdot(q_0, v_0) (or
// a given p_0, see start_momentum), first guess q_0 + h v_0, then the linear
// extrapolation q_k + (h/h_prev)(q_k - q_{k-1}).  Reported velocities: v_0 is
// the given initial velocity and v_k = (q_{k+1} - q_{k-1}) / (h_prev + h) for
// k >= 1 (the central difference), so point k is reported once q_{k+1} is
// known (lag 1).
template <class S, class D>
class DlaStepper {
  static_assert(check_system<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 1;
  // Fixed-point passes of the predictor (next_guess).  A pass is a short
  // chain of dependent operations, cheap in instructions but not in latency,
  // so passes pay only where they end in a guess the residual check accepts
  // (no Jet evaluation and no iteration): the symmetric rule's is exact after
  // its first pass on the structured scenes (the Gauss-Seidel pass,
  // run_passes; the second only confirms it), and any rule's settles at small
  // h.  So a step whose predecessor's guess was accepted makes kMinPasses (one
  // where the first pass is exact, gs_) and goes straight to the check (the
  // check, not a further pass, confirms it); otherwise it makes kMinPasses,
  // or kMaxPasses on every 8th step to find out, and is checked only if a
  // pass moved nothing.
  static constexpr int kMaxPasses = 4, kMinPasses = 2;
  // Passes that take the curvature of a potential of one coordinate (next_guess)
  // converge quadratically: from the extrapolation the third is at round-off
  // and the residual check confirms it (a fourth pass would cost more).
  static constexpr int kNewtonPasses = 3, kMaxNewtonPasses = 5;
  static constexpr double kSqrtEps = 1.4901161193847656e-08;  // 2^-26
  static constexpr double kSettled = 4 * std::numeric_limits<double>::epsilon();
  using Map = DlaMap<S, D>;
  // Do the passes solve for the multipliers too (next_guess)?  Needs V linear
  // in p (a separable system) and no holonomic constraint.
  static constexpr bool kPassesSolveMultipliers = Map::l == 0 && is_separable<S>::value;
  using VecN = Vec<double, n>;
  using VecM = typename Map::VecM;

  DlaStepper(const S& sys, const D& disc, DlaOptions options = {});

  const S& system() const { return map_.system(); }
  const D& discretization() const { return map_.discretization(); }
  const Map& map() const { return map_; }
  // Do the passes (next_guess) see the potential exactly: at the known point
  // only (kappa = 0, no interior node), or through P (a quadratic potential)?
  // Then, where the constraint rows read only coordinates the constraint
  // force does not move, they settle (tests/test_dla.cpp).
  bool passes_exact_in_potential() const { return kPassesSolveMultipliers && (kappa_ == 0 || affine_potential_force_); }
  // Do the passes take the curvature of a potential of one coordinate at
  // every pass (next_guess), so that they converge quadratically?
  bool passes_newton_in_potential() const { return curvature_coordinate_ >= 0; }
  // Is the first pass (Gauss-Seidel, run_passes) exact: kappa = 0 and the
  // constraint rows read only coordinates the constraint force does not move?
  bool first_pass_exact() const { return gs_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = map_.discretization().order();
    t.symmetric = map_.discretization().symmetric();
    t.symmetric_in_phase = false;  // positions only (see the top of this file)
    t.holds_velocity_constraint = false;
    t.implicit = true;
    return t;
  }

  // Start from this p_0 instead of dL/dqdot(q_0, v_0) (e.g. to study the start's
  // effect on the order).  Applies to the next start().
  void start_momentum(const VecN& p0) { p0_ = p0; }

  void start(const VecN& q0, const VecN& v0);

  StepSummary step(double h);

  // The starting iterate of the next step, of size h, from the newest point
  // (q_{k+1}, p_{k+1}).  First step: q_0 + h v_0 and lambda = 0;
  // second step: the linear extrapolation of q and the last multipliers.
  // Otherwise the multipliers, which carry the factor h (L_d does),
  // extrapolate lambda_j / h_j linearly in t from the last two steps (at a
  // change of direction, the stages of a composition: the last multipliers),
  // q starts from the linear extrapolation q_{k+1} + (h / h_k)(q_{k+1} - q_k),
  // and up to `passes` fixed-point passes of eq. (6) follow (at a change of
  // direction only where they settle, refines()).  A pass freezes the
  // nodes q_c and the velocity inside dL/dq at the current guess and solves
  //     sum_c w_c dL/dqdot(q_c, v) = p_{k+1} - omega(q_{k+1})^T lambda
  //                                  + h sum_c w_c (1 - c) dL/dq(q_c, v_guess)   (eq. 6, first line)
  // for v with V(q_cbar, .) (hamiltonian.hpp; exact for a constant mass
  // matrix; cbar = sum_c w_c c); on a separable system with no holonomic
  // constraint it first takes the multipliers from eq. (6), second line, with
  // the constraint nodes frozen too: V is linear in p, so
  //     Omega V(q_cbar, rhs - W^T lambda) = 0,  Omega = sum_c w_c omega(q_c),
  // is m linear equations in lambda (rhs: the right side above without the
  // force).  A pass moves the guess by O(h) times the guess's error (the nodes
  // move the equations by h dL/dq and by omega(q_c) v), so each one gains an
  // order of h (tests/test_dla.cpp).  A pass that moves no coordinate by more
  // than 4 eps of its size is a fixed point of eq. (6): *settled says so, and
  // the solve then starts with a residual check (NewtonSolver::solve).  This
  // happens for the symmetric discretization (alpha = 0) on the separable scenes whose
  // constraint rows read only coordinates the constraint force does not move
  // (the paper's, the contact and chaotic oscillators): there the first pass
  // is exact in those coordinates, which it updates before it takes Omega
  // (Gauss-Seidel, run_passes), and so in all.  A non-finite pass
  // keeps the guess before it.
  //   Rules with an interior node (kappa = sum_c w_c c (1 - c) > 0: alpha = 1/2,
  // the paper's second-order rule) see q_guess in dL/dq too, and frozen there
  // a pass gains only a factor ~ h^2 kappa |d^2 U| (the particle at h = 0.2:
  // ~0.02), too little to settle in kMinPasses, so Newton would follow, with
  // a Jet evaluation, on most steps.  Where dL/dq is affine in q (a
  // quadratic potential: K = d(dL/dq)/dq is constant, found at construction),
  //     dL/dq(q_c) = dL/dq(q_c,guess) + c K (q_next - q_guess),  q_next - q_guess = h (v - v_guess)
  // exactly, and the first line of eq. (6) is
  //     (M - h^2 kappa K) v = rhs - h^2 kappa K v_guess - omega(q_{k+1})^T lambda:
  // the passes use P = (M - h^2 kappa K)^-1 (kept for the last two step sizes:
  // the triple jump and Suzuki's composition alternate between two)
  // instead of V(qbar, .) = M^-1, and are then exact in the potential, so
  // the particle's settle like the symmetric rule's.  At a fixed point the
  // added terms cancel (v = v_guess): it is still the step's solution.  With a
  // non-quadratic potential the same passes with K taken once per step (one
  // Jet evaluation) contract too little to settle in kMinPasses, and the Jet
  // costs more than the passes save: those systems keep the passes above, as
  // do kappa = 0 and K = 0.
  //   Except a potential of one coordinate r (dL/dq reads q_r alone, found by
  // autodiff at construction: the robot's V0 sin psi).  Then K = d(dL/dq)/dq
  // has one column, and every pass takes it at the nodes by a Jet of one
  // derivative, linearizes dL/dq in q_next there, and solves the linearized
  // system (M - u e_r^T) v = ..., Omega v = 0 (u = h^2 sum_c w_c c (1 - c) K e_r):
  // a Newton step in the potential, so the passes converge quadratically, the
  // third is at round-off and the residual check confirms it (kNewtonPasses).
  // The pass solves through the constrained inverse Pi of M, taken again only
  // when Omega changes (run_passes).  (The curvature of every coordinate, a
  // Jet of n derivatives and an n x n inverse per pass, would remove the
  // iterations too, but costs more per step than they do.)
  // extend: Newton passes (a potential of one coordinate) may add passes, up
  // to kMaxNewtonPasses, while the last one moved by more than sqrt(eps) of
  // the state's size (the stepper's own calls; at h = 0.4 three are often
  // not enough).
  void next_guess(double h, VecN* q_guess, VecM* lambda_guess, int passes, bool* settled = nullptr,
                  bool extend = false) const;

 private:
  // next_guess's body, inline so that step() compiles it in place.
  void predict(double h, VecN* q_guess, VecM* lambda_guess, int passes, bool* settled, bool extend) const {
    if (settled) *settled = false;
    polish_ok_ = false;
    if (steps_ == 0) {
      *q_guess = q_curr_ + h * v0_;
      lambda_guess->setZero();
      return;
    }
    *q_guess = extrapolation(h);
    if (!one_direction(h)) {
      *lambda_guess = lambda_;
      if (!refines(h)) return;
    } else {
      *lambda_guess = h * (lambda_ / h_ + (h_ / h_prev_) * (lambda_ / h_ - lambda_prev_ / h_prev_));
    }
    const S& sys = map_.system();
    const D& disc = map_.discretization();
    const VecN& q = q_next_;
    guess_Wt_ = Map::Problem::force_forms(sys, q).transpose();
    const Mat<double, n, Map::mc>& Wt = guess_Wt_;
    double cbar = 0;
    for (const Node& nd : disc.nodes()) cbar += nd.weight * nd.c;
    // Without the multiplier solve the passes converge to a fixed point with
    // the extrapolated multipliers, not to the step: one pass gets all there is.
    if constexpr (!kPassesSolveMultipliers) passes = std::min(passes, 1);
    // The passes only make a starting iterate (Newton or the check judges the
    // result), so they multiply by 1/h: a division is the slowest link of
    // their dependency chain.
    const double inv_h = 1.0 / h;
    // The curvature of the passes (see above): P = (M - h^2 kappa K)^-1, and
    // hkK = h^2 kappa K for the right side.
    Mat<double, n, Map::mc> PWt;
    if constexpr (kPassesSolveMultipliers) {
      // Only where a plain pass gains less than 10^6 (its factor is about
      // rho = h^2 kappa |M^-1 K|): below, two plain passes reach round-off
      // from the extrapolation and P would only cost.
      if (K_) {
        curv_.at(h, [this](double hh) {
          Curvature c;
          c.hkK = (hh * hh * kappa_) * *K_;
          const Mat<double, n, n> MhkK = Minv_ * c.hkK;
          const Mat<double, n, n> G = Mat<double, n, n>::Identity() - MhkK;  // M^-1 (M - h^2 kappa K)
          const double det = G.determinant();
          if (MhkK.cwiseAbs().maxCoeff() >= 1e-6 && std::isfinite(det) &&
              std::abs(det) > 0.5) {  // h^2 kappa K small against M
            c.P = G.inverse() * Minv_;
            c.ok = all_finite(c.P);
          }
          return c;
        });
      }
    }
    const bool curved = K_ && curv_.current().ok;
    if (curved) PWt = curv_.current().P * Wt;
    if constexpr (kPassesSolveMultipliers) {
      polish_curved_ = curved;
    }
    if (curvature_coordinate_ >= 0) {
      run_passes<true>(h, passes, extend, curved, cbar, inv_h, PWt, q_guess, lambda_guess, settled);
    } else {
      run_passes<false>(h, passes, extend, curved, cbar, inv_h, PWt, q_guess, lambda_guess, settled);
    }
  }

 public:
  // The passes of next_guess; kNewton: with the curvature of a potential of
  // one coordinate (a separate instantiation, so that the other passes
  // compile without it: a runtime branch in one shared loop makes the
  // particle's and the contact oscillator's steps slower).
  template <bool kNewton>
  void run_passes(double h, int passes, bool extend, bool curved, double cbar, double inv_h,
                  const Mat<double, n, Map::mc>& PWt, VecN* q_guess, VecM* lambda_guess, bool* settled) const {
    const S& sys = map_.system();
    const D& disc = map_.discretization();
    const VecN& q = q_next_;
    const Mat<double, n, Map::mc>& Wt = guess_Wt_;
    Mat<double, n, Map::mc> MWt;  // M^-1 W^T, for the passes with the curvature of one coordinate
    bool rank_one_started = false;
    // Their constrained inverse Pi for the Omega pi_Om, and S0 (below).
    Mat<double, n, n> pi;
    Mat<double, Map::mc, n> pi_Om;
    Mat<double, Map::mc, Map::mc> pi_S0;
    bool pi_ready = false;
    Mat<double, n, Map::mc> VWt;  // V(q, W^T e_a) (separable: independent of q)
    bool vwt_ready = false;
    // V(q, .) does not depend on q here: the same for every pass (Newton
    // passes can hand over to the plain ones after pass 0, at large h).
    const auto plain_forms = [&](const VecN& qbar) {
      if constexpr (kPassesSolveMultipliers) {
        if (vwt_ready) return;
        for (int a = 0; a < m; ++a) VWt.col(a) = velocity<S, double>(sys, qbar, VecN(Wt.col(a)));
        vwt_ready = true;
      }
    };
    // A potential of one coordinate r (see above): the curvature
    // u = h^2 sum_c w_c c (1 - c) d(dL/dq)/dq_r at the nodes, by a Jet of one
    // derivative at every pass.
    const int r = kNewton ? curvature_coordinate_ : -1;
    for (int pass = 0; pass < passes; ++pass) {
      const VecN vg = (*q_guess - q) * inv_h;
      VecN rhs = p_next_;
      VecN u;
      if constexpr (kNewton) u.setZero();
      bool newton_pass = false;
      for (const Node& nd : disc.nodes()) {
        VecN Lq, Lv;
        if constexpr (kNewton) {
          const VecN qc = (1.0 - nd.c) * q + nd.c * *q_guess;
          const double wcc = nd.weight * nd.c * (1.0 - nd.c);
          if (wcc != 0) {
            VecN dLq;
            partials_and_curvature(sys, qc, vg, r, &Lq, &dLq);
            u += (h * h * wcc) * dLq;
          } else {
            lagrangian_partials(sys, qc, vg, &Lq, &Lv);
          }
        } else {
          lagrangian_partials(sys, VecN((1.0 - nd.c) * q + nd.c * *q_guess), vg, &Lq, &Lv);
        }
        rhs += (h * nd.weight * (1.0 - nd.c)) * Lq;
      }
      const VecN qbar = (1.0 - cbar) * q + cbar * *q_guess;
      VecM lambda = *lambda_guess;
      VecN q1;
      if constexpr (kPassesSolveMultipliers) {
        Mat<double, m, m> Sinv;
        // The curvature of a potential of one coordinate r: the first line of
        // eq. (6), linearized in q_next at the guess, is
        //     (M - u e_r^T) v = rhs - u vg_r - W^T lambda,
        // and (M - u e_r^T)^-1 = (I + z e_r^T / (1 - z_r)) M^-1, z = M^-1 u
        // (Sherman-Morrison), so a pass is a Newton step in the potential (with
        // the constraint nodes frozen).  Only while h^2 curvature is small against M
        // (|1 - z_r| > 1/2, as for P), else the plain pass below.  The pass
        // itself solves through Pi (below); z is kept for that test and for
        // polish(), which applies (M - u e_r^T)^-1 in this form.
        VecN z;
        double zs = 0;
        if constexpr (kNewton) {
          z = Minv_ * u;
          if (std::abs(1.0 - z[r]) > 0.5) zs = 1.0 / (1.0 - z[r]);
        }
        VecN vfree;  // the plain pass's V(qbar, rhs)
        if (gs_) {   // (then kappa = 0: neither curvature applies, the pass is the plain one below)
          plain_forms(qbar);
          // Gauss-Seidel: in a coordinate whose row of V(q, W^T) is zero (one
          // the constraint force does not move) this pass's q1 is
          // q + h V(qbar, rhs), whatever the multipliers, so it goes into the
          // guess before Omega is taken at the constraint nodes.  Where the
          // constraint rows read only such coordinates (passes_settle_) the
          // first pass is then exact in every coordinate, not the second, and
          // with kappa = 0 the stepper makes one pass before the residual
          // check (gs_, step()).  Kept to kappa = 0: on every plain pass it
          // makes the contact oscillator's midpoint DLA slower.
          vfree = velocity<S, double>(sys, qbar, rhs);
          for (int i = 0; i < n; ++i)
            if ((VWt.row(i).array() == 0.0).all()) (*q_guess)[i] = q[i] + h * vfree[i];
        }
        Mat<double, m, n> Om = Mat<double, m, n>::Zero();
        int node = 0;
        for (const Node& nd : disc.constraint_nodes())  // (OmegaMemo: the robot's theta is exact after one pass)
          Om += nd.weight * omega_memo_.at(sys, node++, VecN((1.0 - nd.c) * q + nd.c * *q_guess));
        if (kNewton && zs != 0) {
          if (!rank_one_started) {  // (W^T is the step's: once)
            MWt = Minv_ * Wt;
            rank_one_started = true;
          }
          // The constrained inverse Pi of the plain pass, for this Omega
          // (taken again only when Omega changes: the robot's from pass 1
          // on, theta being exact), so that nothing but Pi times two vectors
          // and one division follows the curvature on the pass's chain:
          // with x = rhs' + v_r u, rhs' = rhs - vg_r u, the system is
          // M v = x - W^T lambda, Omega v = 0, so v = Pi x and
          // lambda = S0 Omega M^-1 x, S0 = (Omega M^-1 W^T)^-1,
          // Pi = M^-1 - M^-1 W^T S0 Omega M^-1; its row r gives
          // v_r = (Pi rhs')_r / (1 - (Pi u)_r).  The same system as the
          // Sherman-Morrison form above, without taking (Omega G W^T)^-1
          // after the curvature at every pass.
          if (!pi_ready || !(Om.array() == pi_Om.array()).all()) {
            pi_Om = Om;
            pi_S0 = Mat<double, m, m>(Om * MWt).inverse();
            pi = Minv_ - MWt * Mat<double, m, n>(pi_S0 * Mat<double, m, n>(Om * Minv_));
            pi_ready = true;
          }
          const VecN rhs1 = rhs - vg[r] * u;
          const VecN Pu = pi * u, Prhs = pi * rhs1;
          const double vr = Prhs[r] / (1.0 - Pu[r]);
          lambda = pi_S0 * VecM(Om * VecN(Minv_ * VecN(rhs1 + vr * u)));
          q1 = q + h * VecN(Prhs + vr * Pu);
          newton_pass = true;
        } else if (curved) {
          const VecN Prhs = curv_.current().P * VecN(rhs - curv_.current().hkK * vg);
          Sinv = Mat<double, m, m>(Om * PWt).inverse();
          lambda = Sinv * VecM(Om * Prhs);
          q1 = q + h * VecN(Prhs - PWt * lambda);
        } else {
          plain_forms(qbar);
          if (!gs_) vfree = velocity<S, double>(sys, qbar, rhs);
          const Mat<double, m, m> A = Om * VWt;
          Sinv = A.inverse();
          lambda = Sinv * VecM(Om * vfree);
          q1 = q + h * velocity<S, double>(sys, qbar, VecN(rhs - Wt * lambda));
        }
        polish_Om_ = Om;  // for polish(), from the last pass
        // (A Newton pass leaves (Omega G W^T)^-1 to polish(), which is rare.)
        polish_lazy_ = newton_pass;
        if (!newton_pass) polish_Sinv_ = Sinv;
        if constexpr (kNewton) {
          polish_zr_ = -1;
          if (zs != 0) {
            polish_z_ = zs * z;
            polish_zr_ = r;
          }
        }
        polish_ok_ = true;
      } else {
        q1 = q + h * velocity<S, double>(sys, qbar, VecN(rhs - Wt * lambda));
      }
      if (!(all_finite(q1) && all_finite(lambda))) return;
      const bool fixed = ((q1 - *q_guess).cwiseAbs() - kSettled * (q.cwiseAbs() + q1.cwiseAbs())).maxCoeff() <= 0;
      [[maybe_unused]] const VecN q_before = *q_guess;
      *q_guess = q1;
      *lambda_guess = lambda;
      if (fixed) {
        if (settled) *settled = true;
        return;
      }
      if constexpr (kNewton)
        if (extend && newton_pass && pass == passes - 1 && passes < kMaxNewtonPasses &&
            (q1 - q_before).cwiseAbs().maxCoeff() > kSqrtEps * (1.0 + q.cwiseAbs().maxCoeff()))
          ++passes;
    }
  }

  // The correction of a guess the residual check accepted by its second test
  // (NewtonSolver::solve: at small h; where the first test, against the terms
  // alone, accepts, the guess is a correctly rounded step without it), from
  // its residual r = (r_f, r_g):
  // one chord Newton step with the step matrix (7) taken as
  // [-G^-1/h  -W^T; Omega/h  0], G = M^-1 (or P, see next_guess) and Omega
  // the last pass's constraint form, i.e. the matrices of that pass:
  //     dlambda = (Omega G W^T)^-1 (Omega G r_f + r_g),
  //     q1 += h G (r_f - W^T dlambda),  lambda += dlambda.
  // The check accepts a point up to 16 eps of its scale from the zero of the
  // residual, and at small h that scale holds |q|/h (solver.hpp), so a guess
  // that is the passes' fixed point, or a pass short of it, could be a few
  // eps |q| off, smoothly from step to step, and such offsets add up to a
  // drift of the mean energy error over long runs (the contact oscillator's
  // midpoint rule at small h) that Newton alone does not have
  // (tests/test_dla.cpp).
  // The correction's fixed point is the zero of the residual, and from a
  // point already at round-off it moves by round-off, so it is taken without
  // another residual.
  void polish(double h, const Vec<double, n + Map::mc>& r, VecN* q1, VecM* lambda) const {
    if constexpr (kPassesSolveMultipliers) {  // (then there is no holonomic multiplier: mc = m)
      if (!polish_ok_) return;
      // G x: P x, M^-1 x, or (I + z e_r^T / (1 - z_r)) M^-1 x (next_guess).
      const auto G = [this](const VecN& x) -> VecN {
        if (polish_curved_) return curv_.current().P * x;
        const VecN y = Minv_ * x;
        if (polish_zr_ < 0) return y;
        return y + y[polish_zr_] * polish_z_;
      };
      if (polish_lazy_) {  // (Omega G W^T)^-1 of the last pass, a Newton pass (run_passes)
        const Mat<double, n, Map::mc> MWt = Minv_ * guess_Wt_;
        const Mat<double, n, Map::mc> GWt = MWt + polish_z_ * MWt.row(polish_zr_);
        polish_Sinv_ = Mat<double, Map::mc, Map::mc>(polish_Om_ * GWt).inverse();
        polish_lazy_ = false;
      }
      const VecN Grf = G(VecN(r.template head<n>()));
      const VecM dl = polish_Sinv_ * VecM(polish_Om_ * Grf + r.template tail<Map::mc>());
      const VecN q = *q1 + h * G(VecN(r.template head<n>() - guess_Wt_ * dl));
      const VecM l = *lambda + dl;
      if (all_finite(q) && all_finite(l)) {
        *q1 = q;
        *lambda = l;
      }
    }
  }

  // The linear extrapolation q_{k+1} + (h / h_k)(q_{k+1} - q_k) (steps >= 1).
  VecN extrapolation(double h) const { return q_next_ + (h / h_) * (q_next_ - q_curr_); }
  // Are this and the last two steps in one direction?  Only then does
  // next_guess extrapolate the multipliers.  The stages of a composition
  // (dla_composition.hpp) go back and forth.
  bool one_direction(double h) const { return steps_ >= 2 && h * h_ > 0 && h_ * h_prev_ > 0; }
  // Does next_guess refine the guess by its passes?  In one direction, or
  // where the passes settle from any start: the constraint force leaves alone
  // what omega reads (constraint_force_misses_omega), so the multipliers'
  // start does not matter and the passes settle as in one direction.  The
  // triple jump's stages then take no Newton iteration where the passes see
  // the potential (the particle, the robot, the symmetric rule), and fewer
  // elsewhere.  On the sleigh (omega reads theta, the force turns it) the
  // passes at a turn cost more than they save: there the stages keep the
  // plain extrapolation.
  bool refines(double h) const { return one_direction(h) || (passes_settle_ && steps_ >= 2); }

  // Point k = steps - 1: (q_k, v_k, p_k, lambda_k, omega_d(q_k, q_{k+1})).
  void sample(Sample<n, m>* s) const;

  // The newest point (q_{k+1}, p_{k+1}) and the last multipliers.
  Vec<double, 2 * n> phase() const {
    Vec<double, 2 * n> z;
    z << q_next_, p_next_;
    return z;
  }
  const VecM& lambda() const { return lambda_; }

 private:
  Map map_;
  std::optional<VecN> p0_;
  // The curvature of the passes (next_guess): M^-1 on a separable system,
  // kappa = sum_c w_c c (1 - c), K = d(dL/dq)/dq when constant, and
  // P = (M - h^2 kappa K)^-1, hkK = h^2 kappa K for a step size (curv_).
  Mat<double, n, n> Minv_ = Mat<double, n, n>::Zero();
  double kappa_ = 0;
  bool affine_potential_force_ = false;             // dL/dq affine in q (K constant, maybe 0)
  std::optional<Mat<double, n, n>> K_;              // K when constant and not 0
  mutable typename Map::Problem::Memo omega_memo_;  // omega at the constraint nodes (OmegaMemo)
  mutable Mat<double, n, Map::mc> guess_Wt_ =
      Mat<double, n, Map::mc>::Zero();  // force_forms(q_{k+1})^T, by next_guess (for the solve and polish())
  struct Curvature {
    Mat<double, n, n> P = Mat<double, n, n>::Zero(), hkK = Mat<double, n, n>::Zero();
    bool ok = false;
  };
  mutable StepSizeCache<Curvature> curv_;  // current(): this step's
  // Set by start(); zero until then (so that an unstarted stepper copies cleanly).
  VecN q_prev_ = VecN::Zero(), q_curr_ = VecN::Zero(), q_next_ = VecN::Zero(), p_curr_ = VecN::Zero(),
       p_next_ = VecN::Zero(), v0_ = VecN::Zero();
  VecM lambda_ = VecM::Zero(), lambda_prev_ = VecM::Zero();
  long steps_ = 0;
  double h_ = 0, h_prev_ = 0;
  bool passes_settle_ = false;  // constraint_force_misses_omega (separable systems)
  bool gs_ = false;             // passes_settle_ and kappa = 0: one pass after an accepted guess
  bool accepted_ = false;       // did the residual check accept the last step's guess?
  // The last pass's matrices for polish(): Omega, (Omega G W^T)^-1, and G = P or M^-1 (W^T: guess_Wt_).
  mutable Mat<double, Map::mc, n> polish_Om_ = Mat<double, Map::mc, n>::Zero();
  mutable Mat<double, Map::mc, Map::mc> polish_Sinv_ = Mat<double, Map::mc, Map::mc>::Zero();
  mutable bool polish_curved_ = false, polish_ok_ = false;
  mutable bool polish_lazy_ = false;      // polish_Sinv_ is still to be taken (a Newton pass)
  mutable VecN polish_z_ = VecN::Zero();  // z / (1 - z_r) of the last pass, and r (-1: none)
  mutable int polish_zr_ = -1;
  // The one coordinate the potential reads when the passes take its curvature (-1: they do not).
  int curvature_coordinate_ = -1;
};

}  // namespace nhi
