// The implicit solve, generic over a residual functor: Newton's method on exact
// ceres::Jet derivatives, a Schur-complement solve that exploits multipliers
// entering linearly, reuse of the factorization while the iteration contracts,
// and ceres::TinySolver (Levenberg-Marquardt) as the fallback.  The shape is
// Ceres' tiny_solver.h: a functor, nested Options, a Summary.
//
// A Problem has unknowns x = (y, lambda), y in R^ny and lambda in R^nl, and a
// residual of saddle-point form
//     r(y, lambda) = ( f(y) - Wt lambda ,  g(y) )        (ny + nl rows)
// with Wt a fixed ny x nl matrix during the solve (nl = 0 is a plain system).
// The DLA step (dla.hpp, eq. 6) is of this form with y = q_{k+1} and
// Wt = omega(q_k)^T; its Jacobian is the matrix (7).  A Problem provides
//   static constexpr int ny, nl;
//   const Mat<double, ny, nl>& Wt() const;
//   template <class T> void residual(const Vec<T,ny>& y, const Vec<T,nl>& lambda,
//                                    Vec<T,ny+nl>* r, Vec<double,ny+nl>* terms) const;
//   Vec<double, ny> y_scale(const Vec<double, ny>& y) const;
// residual() is called with T = double and T = ceres::Jet<double, ny> (y seeded,
// lambda constant; the fallback's lambda-columns are (-Wt; 0), by the form).  A
// Problem with many unknowns whose residual couples them through small blocks
// (SPARK's stages, spark.hpp) may instead provide
//   void jacobian(const Vec<double,ny>& y, const Vec<double,nl>& lambda, Mat<double,ny+nl,ny>* Jy) const;
// the residual's y-Jacobian (its lambda-Jacobian is (-Wt; 0) by the form
// above); residual() is then only called with T = double.  `terms`
// (may be null) gets per row the sum of magnitudes of what r_i adds up.  The
// relative residual of row i is |r_i| / (terms_i + sum_j |dr_i/dy_j| y_scale_j):
// the second part is the residual a unit relative change of y causes, so the
// floor it sets is the round-off of y itself (e.g. in (q1 - q0)/h when |q| is large).
// A Problem whose residual reads quantities it computes from y (mp06's
// separable form: q1 = q_half + (h/2) V(p1(lambda))) may also provide
//   void rounding_terms(const Vec<double,ny>& y, const Vec<double,nl>& lambda,
//                       Vec<double,ny+nl>* extra) const;
// extra_i = sum_k |dr_i/du_k| |u_k| over those quantities u that move with
// y: the residual their own rounding (a relative eps each, like y's) can
// cause, which the derivatives in y do not show when u is much larger than
// its change with y.  (A quantity that does not move with y is a fixed input
// of the solve, whose rounding Newton solves around: not counted.)  It is
// part of the scale of relative_residual() and of the fallback's final
// check; newton() computes it only for a residual within tolerance but above
// 16 eps of the scale without it, where it decides between accepting and
// iterating (has_rounding_terms below).
//   Root following.  At a large h the equations of an implicit step can have
// several roots, and the start decides which one Newton finds.  A Problem
// that also provides
//   P at_step(double h2) const;   // the same step (same state) at step size h2
//   void small_step_start(double ratio, Vec<double,ny>* y, Vec<double,nl>* lambda) const;
//       // a start for step ratio*h from one for h: the root's h -> 0 limit
//       // plus ratio times the start's offset from it (ratio = 0: the limit)
// and a member `double h` can be solved along the root continued from h -> 0
// (SolverOptions::continuation): natural-parameter continuation in h with
// sub-steps of at most continuation_dh (at least two), each started from the
// secant through the last two roots (the first from the root's h -> 0
// limit), Newton only (the fallback could jump branches), the sub-step halved (down to 1/64 of it) where Newton fails.
// If that still fails, the branch from h -> 0 has folded before h (or turned
// too sharply to follow), and the step has no continued root.  With
// root_check the step is solved from the caller's start as usual and then
// continued as well, and StepSummary::root says whether the two agree
// (has_continuation below).
#pragma once

#include <ceres/tiny_solver.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>

#include "nhi/roles/stepper.hpp"

namespace nhi {

// Does the Problem provide rounding_terms() (above)?
// Does the Problem provide at_step() and small_step_start() (above)?
template <class P, class = void>
struct has_continuation : std::false_type {};
template <class P>
struct has_continuation<P,
                        std::void_t<decltype(std::declval<const P&>().at_step(0.0)),
                                    decltype(std::declval<const P&>().small_step_start(
                                        0.0, std::declval<Vec<double, P::ny>*>(), std::declval<Vec<double, P::nl>*>())),
                                    decltype(std::declval<const P&>().h)>> : std::true_type {};

// Does the Problem provide its own y-Jacobian (above)?
template <class P, class = void>
struct has_jacobian : std::false_type {};
template <class P>
struct has_jacobian<P, std::void_t<decltype(std::declval<const P&>().jacobian(
                           std::declval<const Vec<double, P::ny>&>(), std::declval<const Vec<double, P::nl>&>(),
                           std::declval<Mat<double, P::ny + P::nl, P::ny>*>()))>> : std::true_type {};

template <class P, class = void>
struct has_rounding_terms : std::false_type {};
template <class P>
struct has_rounding_terms<P, std::void_t<decltype(std::declval<const P&>().rounding_terms(
                                 std::declval<const Vec<double, P::ny>&>(), std::declval<const Vec<double, P::nl>&>(),
                                 std::declval<Vec<double, P::ny + P::nl>*>()))>> : std::true_type {};

struct SolverOptions {
  double tolerance = kDefaultTolerance;  // required relative residual
  int max_iterations = 20;               // Newton iterations before the fallback
  bool fallback = true;                  // retry a failed Newton with ceres::TinySolver
  // Keep the factorization (a chord step) while each iteration shrinks the
  // relative residual by at least this factor; refresh the Jacobian otherwise.
  double refresh_ratio = 1e-3;
  // Root following (above): solve along the root continued from h -> 0
  // instead of from the caller's start; or solve from the start and report
  // whether its root is the continued one (StepSummary::root).
  bool continuation = false;
  bool root_check = false;
  double continuation_dh = 0.05;  // largest sub-step of the continuation in h
  bool follows_roots() const { return continuation || root_check; }
};

template <class P>
class NewtonSolver {
 public:
  static constexpr int ny = P::ny, nl = P::nl, N = ny + nl;
  using VecY = Vec<double, ny>;
  using VecL = Vec<double, nl>;
  using VecX = Vec<double, N>;
  using Options = SolverOptions;
  using Summary = StepSummary;
  // A relative residual at round-off (newton() and the residual check).
  static constexpr double kRoundoff = 16 * std::numeric_limits<double>::epsilon();

  explicit NewtonSolver(const P& problem, Options options = {}) : p_(problem), options_(options) {}

  // No correction of an accepted guess (solve()).
  struct NoPolish {
    void operator()(const VecX&, VecY*, VecL*) const {}
  };

  // Solve from (y, lambda) in place; on failure y and lambda keep the guess.
  // check_guess: the guess may already be a solution (a converged predictor,
  // dla.hpp), so first test it with one residual and no derivatives.  A guess
  // accepted by the second test (guess_converged: at small h, where the scale
  // holds the round-off of (q1 - q0)/h) then gets polish(r, &y, &lambda), r its
  // residual: one correction toward the zero of the residual with an
  // approximate inverse of the step matrix the caller has at hand (the DLA:
  // its passes' matrices), since that test accepts a point up to 16 eps of a
  // scale ~|y|/h away, and a predictor's error is smooth from step to step
  // (dla_predictor_body.hpp, DlaPredictor::polish).
  template <class Polish = NoPolish>
  Summary solve(VecY* y, VecL* lambda, bool check_guess = false, const Polish& polish = {}) const {
    if constexpr (has_continuation<P>::value) {
      if (options_.continuation) {
        VecY yc = *y;
        VecL lc = *lambda;
        Summary s = continued(&yc, &lc, true);
        if (s.ok()) {
          *y = yc;
          *lambda = lc;
          s.root = RootCheck::kContinued;
        }
        return s;
      }
      if (options_.root_check) {
        const VecY y0 = *y;
        const VecL l0 = *lambda;
        Summary s = solve_from_start(y, lambda, check_guess, polish);
        if (s.ok()) s.root = check_root(*y, *lambda, y0, l0);
        return s;
      }
    }
    return solve_from_start(y, lambda, check_guess, polish);
  }

  // Is the solution (y, lambda) the root continued from h -> 0, starting the
  // continuation from (y_start, l_start)?  (kUnchecked for a Problem without
  // continuation.)
  RootCheck check_root(const VecY& y, const VecL& lambda, VecY y_start, VecL l_start) const {
    if constexpr (has_continuation<P>::value) {
      const Summary c = continued(&y_start, &l_start, false);
      if (!c.ok()) return RootCheck::kNotFound;
      return same_root(y, lambda, y_start, l_start) ? RootCheck::kContinued : RootCheck::kOther;
    } else {
      return RootCheck::kUnchecked;
    }
  }

  // Do two solutions agree beyond the solver's tolerance (1e-6 relative to
  // their size plus one: distinct roots differ at the size of the state)?
  static bool same_root(const VecY& y1, const VecL& l1, const VecY& y2, const VecL& l2) {
    const auto close = [](const auto& a, const auto& b) {
      if constexpr (std::decay_t<decltype(a)>::SizeAtCompileTime == 0) {
        return true;
      } else {
        return (a - b).cwiseAbs().maxCoeff() <= 1e-6 * (1.0 + a.cwiseAbs().maxCoeff());
      }
    };
    return close(y1, y2) && close(l1, l2);
  }

 private:
  // The root continued from h -> 0 (above), from the start (y, lambda) for
  // h; in_place: the last solve, at h itself, on this solver's problem (whose
  // caches the caller reads), else on a copy.
  Summary continued(VecY* y, VecL* lambda, bool in_place) const {
    const double h = p_.h;
    const int K = std::max(2, static_cast<int>(std::ceil(std::abs(h) / options_.continuation_dh)));
    Options sub = options_;
    sub.continuation = sub.root_check = false;
    sub.fallback = false;
    Summary total;
    // (y_prev, l_prev) at parameter sa and (y_cur, l_cur) at sb are the last
    // two points of the branch, in units of h; the first is the h -> 0 limit.
    VecY y_prev = *y, y_cur = *y;
    VecL l_prev = *lambda, l_cur = *lambda;
    p_.small_step_start(0.0, &y_prev, &l_prev);
    double sa = 0, sb = 0, ds = 1.0 / K;
    const double ds_min = ds / 64;
    while (sb < 1) {
      const double s_next = std::min(1.0, sb + ds);
      VecY yt;
      VecL lt;
      if (sb == 0) {  // the h -> 0 limit itself (the caller's start enters only through a multiplier that has one)
        yt = y_prev;
        lt = l_prev;
      } else {  // the secant through the last two points
        const double w = (s_next - sb) / (sb - sa);
        yt = y_cur + w * (y_cur - y_prev);
        lt = l_cur + w * (l_cur - l_prev);
      }
      Summary s;
      if (s_next == 1 && in_place) {
        s = NewtonSolver<P>(p_, sub).solve_from_start(&yt, &lt, false, NoPolish{});
      } else {
        const P pj = p_.at_step(s_next * h);
        s = NewtonSolver<P>(pj, sub).solve_from_start(&yt, &lt, false, NoPolish{});
      }
      total.add_cost(s);
      if (!s.ok()) {
        if (ds > ds_min) {
          ds *= 0.5;
          continue;
        }
        total.status = SolveStatus::kFailed;
        total.failure = s.failure == FailureKind::kNonFinite ? FailureKind::kNonFinite : FailureKind::kSolve;
        total.message = "no root continued from h -> 0 beyond h = " + std::to_string(sb * h) + " (of " +
                        std::to_string(h) + "): " + s.message;
        return total;
      }
      if (sb > 0) {
        y_prev = y_cur;
        l_prev = l_cur;
      }
      sa = sb;
      sb = s_next;
      y_cur = yt;
      l_cur = lt;
      total.relative_residual = s.relative_residual;
      ds = std::min(2 * ds, 1.0 / K);
    }
    total.status = SolveStatus::kConverged;
    *y = y_cur;
    *lambda = l_cur;
    return total;
  }

 public:
  // solve() from the caller's start (y, lambda), without root following.
  template <class Polish>
  Summary solve_from_start(VecY* y, VecL* lambda, bool check_guess, const Polish& polish) const {
    if (check_guess) {
      Summary s;
      VecX r;
      bool by_bound = false;
      if (guess_converged(*y, *lambda, &s, &r, &by_bound)) {
        if (by_bound) polish(r, y, lambda);
        return s;
      }
    }
    Summary s = newton(y, lambda);
    if (s.status != SolveStatus::kConverged && options_.fallback) {
      Summary f = tiny_solver(y, lambda);
      f.add_cost(s);
      f.used_fallback = true;
      if (f.status != SolveStatus::kConverged) {
        f.message = "Newton: " + s.message + "; TinySolver fallback: " + f.message;
        f.failure = s.failure == FailureKind::kNonFinite ? FailureKind::kNonFinite : FailureKind::kSolve;
      }
      s = f;
    }
    return s;
  }

  // Relative residual at (y, lambda), its scale with the rounding terms
  // (has_rounding_terms); *r_out gets the residual.
  double relative_residual(const VecY& y, const VecL& lambda, VecX* r_out = nullptr) const {
    VecX r;
    Mat<double, N, ny> Jy;
    const double rel = evaluate(y, lambda, &r, &Jy, nullptr, true);
    if (r_out) *r_out = r;
    return rel;
  }

 private:
  static double ratio(double r, double scale) {
    if (!std::isfinite(r) || !std::isfinite(scale)) return std::numeric_limits<double>::infinity();
    if (r == 0) return 0;
    return std::abs(r) / std::max(scale, std::numeric_limits<double>::min());
  }

  // Residual and its y-Jacobian by one Jet evaluation; returns the relative residual.
  // *scale_out (optional) gets the whole scale of each row at y: the terms of
  // the residual plus sum_j |dr_i/dy_j| y_scale_j, plus the rounding terms
  // (has_rounding_terms) when with_rounding.
  double evaluate(const VecY& y, const VecL& lambda, VecX* r, Mat<double, N, ny>* Jy, VecX* scale_out = nullptr,
                  bool with_rounding = false) const {
    VecX terms;
    if constexpr (has_jacobian<P>::value) {
      p_.template residual<double>(y, lambda, r, &terms);
      p_.jacobian(y, lambda, Jy);
    } else {
      using J = ceres::Jet<double, ny>;
      Vec<J, ny> yj;
      for (int i = 0; i < ny; ++i) yj[i] = J(y[i], i);
      const Vec<J, nl> lj = lambda.template cast<J>();
      Vec<J, N> rj;
      p_.template residual<J>(yj, lj, &rj, &terms);
      for (int i = 0; i < N; ++i) {
        (*r)[i] = rj[i].a;
        for (int j = 0; j < ny; ++j) (*Jy)(i, j) = rj[i].v[j];
      }
    }
    const VecY ys = p_.y_scale(y);
    if constexpr (has_rounding_terms<P>::value) {
      if (with_rounding) {
        VecX extra;
        p_.rounding_terms(y, lambda, &extra);
        terms += extra;
      }
    }
    double rel = 0;
    for (int i = 0; i < N; ++i) {
      double scale = terms[i];
      for (int j = 0; j < ny; ++j) scale += std::abs((*Jy)(i, j)) * ys[j];
      if (scale_out) (*scale_out)[i] = scale;
      rel = std::max(rel, ratio((*r)[i], scale));
    }
    return rel;
  }

  // The residual alone (no derivatives and no sizes of its terms), judged with
  // the scale of the point whose Jacobian the chord iterations use: near the
  // solution the sizes of the terms change by the relative size of the step,
  // which does not matter to a threshold, and skipping them halves the cost of
  // a residual.
  double evaluate_value(const VecY& y, const VecL& lambda, const VecX& scale, VecX* r) const {
    p_.template residual<double>(y, lambda, r, nullptr);
    double rel = 0;
    for (int i = 0; i < N; ++i) rel = std::max(rel, ratio((*r)[i], scale[i]));
    return rel;
  }

  // Is (y, lambda) a solution at round-off by newton()'s first test
  // (rel <= 16 eps), without derivatives?  First against the sizes of the
  // terms alone: a smaller scale than newton()'s, so what passes, newton()
  // would accept unchanged.  At small h that scale is too small: the
  // round-off of (q1 - q0)/h grows like 1/h, and newton() sees it in the
  // Jacobian part of its scale, sum_j |dr_i/dy_j| y_scale_j.  A guess that
  // fails gets a second test with half a lower bound of that part, from
  // residuals at y + d, d_j = +-delta y_scale_j:
  //     |r_i(y + d) - r_i(y)| / delta = |sum_j +-dr_i/dy_j y_scale_j| + O(delta)
  //                                  <= sum_j |dr_i/dy_j| y_scale_j
  // for any signs.  With delta = 2^-20 the O(delta) curvature and the
  // 2 eps / delta of round-off in the difference are far inside the factor
  // 1/2, so this too accepts only what newton() would.  One probe along
  // +y_scale serves the rows of f (for the DLA, ~ -M/h); a row of g that still
  // fails gets one along the signs of its multiplier's column of Wt (for the
  // DLA, d omega_d/dq1 ~ omega/h and Wt = omega(q_k)^T), which do not cancel.
  // (At h = 0.4 / 2^9 the first test alone fails on almost every step of the
  // symmetric DLA, and each would pay a Jet evaluation for zero iterations.)
  // *r_out (optional) gets the residual of an accepted guess, and *by_bound
  // whether it took the second test.
  bool guess_converged(const VecY& y, const VecL& lambda, Summary* s, VecX* r_out = nullptr,
                       bool* by_bound = nullptr) const {
    constexpr double kDelta = 1.0 / (1 << 20);
    VecX r, terms;
    p_.template residual<double>(y, lambda, &r, &terms);
    double rel = 0;
    for (int i = 0; i < N; ++i) rel = std::max(rel, ratio(r[i], terms[i]));
    int evaluations = 1;
    const bool second = !(rel <= kRoundoff);
    if (second) {
      // Probe 0 along +y_scale; for the rows of g, which can cancel along it,
      // one probe per failing row with the signs of its multiplier's column of
      // Wt (the DLA's d omega_d / dq1 is omega / h, and Wt = omega(q_k)^T).
      const VecY ys = p_.y_scale(y);
      VecX rd, bound = VecX::Zero();
      for (int probe = 0; probe <= nl; ++probe) {
        VecY d = kDelta * ys;
        if (probe > 0) {
          const int row = ny + probe - 1;
          if (ratio(r[row], terms[row] + (0.5 / kDelta) * bound[row]) <= kRoundoff) continue;
          for (int j = 0; j < ny; ++j)
            if (p_.Wt()(j, probe - 1) < 0) d[j] = -d[j];
        }
        ++evaluations;
        p_.template residual<double>(VecY(y + d), lambda, &rd, nullptr);
        for (int i = 0; i < N; ++i) bound[i] = std::max(bound[i], std::abs(rd[i] - r[i]));
        if (probe == 0)
          for (int i = 0; i < ny; ++i)  // rows of f: no later probe is for them
            if (!(ratio(r[i], terms[i] + (0.5 / kDelta) * bound[i]) <= kRoundoff)) return false;
      }
      rel = 0;
      for (int i = 0; i < N; ++i) rel = std::max(rel, ratio(r[i], terms[i] + (0.5 / kDelta) * bound[i]));
    }
    if (!(rel <= kRoundoff && rel <= options_.tolerance)) return false;
    if (r_out) *r_out = r;
    if (by_bound) *by_bound = second;
    s->status = SolveStatus::kConverged;
    s->iterations = 0;
    s->evaluations = evaluations;
    s->relative_residual = rel;
    return true;
  }

  // x^k for a small fixed k (std::pow would be a noticeable share of a DLA step).
  template <int k>
  static double power(double x) {
    double p = 1;
    for (int i = 0; i < k; ++i) p *= x;
    return p;
  }

  // Solves the linear system with the matrix [A  -Wt; B  0], A = df/dy, B = dg/dy.
  // While A is comfortably invertible (for the DLA A ~ -M/h) by the Schur
  // complement with closed-form inverses of A and of B A^-1 Wt (ny, nl <= 4),
  // else by pivoted LU of the whole matrix.
  class LinearSolver {
   public:
    explicit LinearSolver(const Mat<double, ny, nl>& Wt) : Wt_(Wt) {}
    void factor(const Mat<double, N, ny>& Jy) {
      const Mat<double, ny, ny> A = Jy.template topRows<ny>();
      B_ = Jy.template bottomRows<nl>();
      schur_ok_ = false;
      if constexpr (ny <= 4 && nl > 0 && nl <= 4) {
        // Closed-form inverses of the fixed-size A and Schur complement (Eigen's
        // cofactor formulas for n <= 4): |det| against the size of the entries,
        // as det scales, relative 1e-10.
        const double detA = A.determinant();
        if (std::isfinite(detA) && std::abs(detA) > 1e-10 * power<ny>(A.cwiseAbs().maxCoeff())) {
          Ainv_ = A.inverse();
          AinvWt_ = Ainv_ * Wt_;
          const Mat<double, nl, nl> Sm = B_ * AinvWt_;  // Schur complement B A^-1 Wt
          const double detS = Sm.determinant();
          if (std::isfinite(detS) && std::abs(detS) > 1e-10 * power<nl>(Sm.cwiseAbs().maxCoeff())) {
            Sinv_ = Sm.inverse();
            schur_ok_ = all_finite(Sinv_);
          }
        }
      }
      if (!schur_ok_) {
        Mat<double, N, N> K = Mat<double, N, N>::Zero();
        K.template leftCols<ny>() = Jy;
        if constexpr (nl > 0) K.template topRightCorner<ny, nl>() = -Wt_;
        lu_.compute(K);
      }
    }
    VecX solve(const VecX& r) const {
      if constexpr (ny <= 4 && nl > 0 && nl <= 4) {
        if (schur_ok_) {
          // A dy - Wt dl = r1,  B dy = r2  =>  (B A^-1 Wt) dl = r2 - B A^-1 r1.
          const VecY z = Ainv_ * r.template head<ny>();
          const VecL dl = Sinv_ * VecL(r.template tail<nl>() - B_ * z);
          VecX dx;
          dx.template head<ny>() = z + AinvWt_ * dl;
          dx.template tail<nl>() = dl;
          return dx;
        }
      }
      return lu_.solve(r);
    }

   private:
    Mat<double, ny, nl> Wt_;
    Mat<double, nl, ny> B_;
    Mat<double, ny, ny> Ainv_;
    Mat<double, ny, nl> AinvWt_;
    Mat<double, nl, nl> Sinv_;
    Eigen::PartialPivLU<Mat<double, N, N>> lu_;
    bool schur_ok_ = false;
  };

  // Newton's iterate and what newton() keeps from one iteration to the next.
  struct Iterate {
    explicit Iterate(const Mat<double, ny, nl>& Wt) : solver(Wt) {}
    VecY y;
    VecL lambda;
    double prev = std::numeric_limits<double>::infinity();  // the last iteration's relative residual
    VecX r;
    Mat<double, N, ny> Jy;
    LinearSolver solver;
    bool fresh = true;     // r, Jy were just evaluated with derivatives at the iterate
    VecX scale;            // of the rows, at the point of the last Jacobian
    double rel = 0;        // the relative residual of r
    bool rounded = false;  // the rounding terms are in scale
  };

  // Newton with the Jacobian refreshed only when the last step contracted the
  // residual by less than 1e-3 (otherwise the factorization is reused): near
  // round-off the converged iterate is the same, with fewer Jet passes.
  // Converged: within tolerance, and at round-off or no longer improving
  // (accepts), after the start's own update if it is the start (start_update).
  Summary newton(VecY* y_io, VecL* lambda_io) const {
    Summary s;
    Iterate x(p_.Wt());
    x.y = *y_io;
    x.lambda = *lambda_io;
    x.rel = evaluate(x.y, x.lambda, &x.r, &x.Jy, &x.scale);
    ++s.evaluations;
    ++s.jacobians;
    for (int it = 0;; ++it) {
      s.relative_residual = x.rel;
      if (!std::isfinite(x.rel)) {
        s.message = "non-finite residual";
        s.failure = FailureKind::kNonFinite;
        return s;
      }
      add_rounding_terms(&x, &s);
      if (accepts(x)) {
        if (it == 0) start_update(&x);
        break;
      }
      if (it == options_.max_iterations) {
        if (x.rel <= options_.tolerance) break;
        s.message =
            "no convergence in " + std::to_string(it) + " iterations (relative residual " + std::to_string(x.rel) + ")";
        s.failure = FailureKind::kSolve;
        return s;
      }
      if (!iterate(&x, &s)) {
        s.message = "singular step matrix (eq. 7)";
        s.failure = FailureKind::kSolve;
        return s;
      }
    }
    *y_io = x.y;
    *lambda_io = x.lambda;
    s.status = SolveStatus::kConverged;
    return s;
  }

  // The rounding terms (has_rounding_terms), where they can decide: they
  // only grow the scale, so a residual at 16 eps without them does not
  // need them, and one above tolerance without them is not accepted
  // (stricter than the whole scale only where the rounding terms exceed
  // tolerance / (16 eps), ~280 times, the rest of it).  Evaluated at the
  // iterate, counted as an evaluation.
  void add_rounding_terms(Iterate* x, Summary* s) const {
    if constexpr (has_rounding_terms<P>::value) {
      if (!x->rounded && x->rel <= options_.tolerance && !(x->rel <= kRoundoff)) {
        VecX extra;
        p_.rounding_terms(x->y, x->lambda, &extra);
        ++s->evaluations;
        x->scale += extra;
        x->rounded = true;
        x->rel = 0;
        for (int i = 0; i < N; ++i) x->rel = std::max(x->rel, ratio(x->r[i], x->scale[i]));
        s->relative_residual = x->rel;
      }
    }
  }

  // Converged: within tolerance, and at round-off or no longer improving.
  bool accepts(const Iterate& x) const {
    return x.rel <= options_.tolerance && (x.rel <= kRoundoff || x.rel > 0.5 * x.prev);
  }

  // A start that is already at round-off still takes the update its first
  // evaluation paid the Jacobian for (no new evaluation; not counted as an
  // iteration, like DlaPredictor::polish): otherwise an accepted start keeps
  // its error, and where the solution moves by round-off from step to step
  // the residual of the next start creeps past the round-off test (mp06 on
  // the sleigh, where lambda = 0 while it runs straight: without the update
  // the residual of the last multiplier grows by ~2e-16 a step until it
  // passes 16 eps of its scale, and an iteration follows).
  void start_update(Iterate* x) const {
    x->solver.factor(x->Jy);
    const VecX dx = x->solver.solve(x->r);
    if (all_finite(dx)) {
      x->y -= dx.template head<ny>();
      x->lambda -= dx.template tail<nl>();
    }
  }

  // One Newton (or chord) iteration and the residual after it; the Jacobian
  // again where it contracted by less than refresh_ratio.  False where the
  // step matrix is singular.
  bool iterate(Iterate* x, Summary* s) const {
    if (x->fresh) x->solver.factor(x->Jy);
    const VecX dx = x->solver.solve(x->r);
    if (!all_finite(dx)) return false;
    x->y -= dx.template head<ny>();
    x->lambda -= dx.template tail<nl>();
    x->prev = x->rel;
    ++s->iterations;
    x->rel = evaluate_value(x->y, x->lambda, x->scale, &x->r);
    ++s->evaluations;
    x->fresh = false;
    if (!(x->rel <= options_.refresh_ratio * x->prev) && !(x->rel <= kRoundoff)) {  // slow contraction: refresh
      x->rel = evaluate(x->y, x->lambda, &x->r, &x->Jy, &x->scale);
      ++s->evaluations;
      ++s->jacobians;
      x->fresh = true;
      x->rounded = false;
    }
    return true;
  }

 public:
  // The residual and its Jacobian in all N unknowns for ceres::TinySolver,
  // column-major: the y-columns from evaluate() (the Problem's own Jacobian
  // or the Jet pass Newton uses), the lambda-columns (-Wt; 0) by the
  // saddle-point form (top of this file).  The same numbers as Jets over all
  // N unknowns (ceres::TinySolverAutoDiffFunction) would give, derivative by
  // derivative, without compiling the residual for a second Jet width.
  struct FallbackCost {
    using Scalar = double;
    enum { NUM_RESIDUALS = N, NUM_PARAMETERS = N };
    const NewtonSolver* solver;
    bool operator()(const double* x, double* residuals, double* jacobian) const {
      const VecY y = Eigen::Map<const VecY>(x);
      const VecL lambda = Eigen::Map<const VecL>(x + ny);
      Eigen::Map<VecX> res(residuals);
      if (!jacobian) {
        VecX r;
        solver->p_.template residual<double>(y, lambda, &r, nullptr);
        res = r;
        return true;
      }
      VecX r;
      Mat<double, N, ny> Jy;
      solver->evaluate(y, lambda, &r, &Jy);
      res = r;
      Eigen::Map<Mat<double, N, N>> J(jacobian);
      J.template leftCols<ny>() = Jy;
      if constexpr (nl > 0) {
        J.template topRightCorner<ny, nl>() = -solver->p_.Wt();
        J.template bottomRightCorner<nl, nl>().setZero();
      }
      return true;
    }
  };

 private:
  // The fallback: ceres::TinySolver (Levenberg-Marquardt) on FallbackCost.
  Summary tiny_solver(VecY* y_io, VecL* lambda_io) const {
    const FallbackCost cost{this};
    ceres::TinySolver<FallbackCost> solver;
    Summary s;
    solver.options.max_num_iterations = 200;
    solver.options.gradient_tolerance = 0;
    solver.options.parameter_tolerance = 1e-15;  // relative step below round-off: stop
    solver.options.function_tolerance = 0;       // (2.1: this one is absolute)
    solver.options.cost_threshold = 0;
    VecX x;
    x.template head<ny>() = *y_io;
    x.template tail<nl>() = *lambda_io;
    const auto& summary = solver.Solve(cost, &x);
    s.iterations = summary.iterations;
    s.evaluations = summary.iterations + 1;
    s.jacobians = s.evaluations;  // TinySolver differentiates at every evaluation
    const VecY y = x.template head<ny>();
    const VecL lambda = x.template tail<nl>();
    VecX r;
    Mat<double, N, ny> Jy;
    s.relative_residual = evaluate(y, lambda, &r, &Jy, nullptr, true);
    if (std::isfinite(s.relative_residual) && s.relative_residual <= options_.tolerance) {
      *y_io = y;
      *lambda_io = lambda;
      s.status = SolveStatus::kConverged;
    } else {
      s.message = "relative residual " + std::to_string(s.relative_residual) + " after " +
                  std::to_string(summary.iterations) + " iterations";
      s.failure = FailureKind::kSolve;
    }
    return s;
  }

  const P& p_;
  Options options_;
};

}  // namespace nhi
