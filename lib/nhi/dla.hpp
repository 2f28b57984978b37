// The DLA *stepper*: one step of the discrete Lagrange-d'Alembert algorithm
// (paper eq. 6) in position-momentum form.  Given (q_k, p_k) with
// p_k = D2 L_d(q_{k-1}, q_k), solve the n+m equations
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
//
// Solver: Newton's method with the q_{k+1}-block of (7) from ceres::Jet
// autodiff (lambda enters linearly, so its column is omega(q_k)^T, fixed during
// the step) and a fixed-size LU solve.  If Newton fails (no convergence, a
// singular or non-finite step) the step is retried from the same guess with
// ceres::TinySolver (Levenberg-Marquardt on the same residual, full Jet
// Jacobian).  Convergence is judged on the residual relative to the size of
// the terms it sums, so it means the same at |q| = 1 and |q| = 1e6.
#pragma once

#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include <Eigen/LU>
#include <algorithm>
#include <limits>
#include <string>

#include "nhi/discretization.hpp"

namespace nhi {

enum class SolveStatus { kConverged, kFailed };

struct StepSummary {
  SolveStatus status = SolveStatus::kFailed;
  int iterations = 0;            // Newton iterations (plus TinySolver's, if it ran)
  int evaluations = 0;           // residual(+Jacobian) evaluations
  double relative_residual = 0;  // final max_i |r_i| / size of the terms of r_i
  bool used_fallback = false;
  std::string message;  // why it failed, when it did
};

struct DlaOptions {
  double tolerance = 1e-12;  // required relative residual
  int max_iterations = 20;   // Newton iterations before the fallback
  bool fallback = true;      // retry failed steps with ceres::TinySolver
};

template <class S, class D>
class DlaStepper {
 public:
  static constexpr int n = S::n;
  static constexpr int m = S::m;                       // nonholonomic constraints omega
  static constexpr int l = holonomic_count<S>::value;  // holonomic constraints g (eq. 17)
  static constexpr int mc = m + l;                     // multipliers (mu, lambda)
  static constexpr int N = n + mc;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, mc>;
  using VecX = Vec<double, N>;

  DlaStepper(const S& sys, const D& disc, double h, DlaOptions options = {})
      : sys_(sys), disc_(disc), h_(h), options_(options) {}

  const S& system() const { return sys_; }
  const D& discretization() const { return disc_; }
  double h() const { return h_; }
  int order() const { return disc_.order(); }
  bool symmetric() const { return disc_.symmetric(); }
  static constexpr bool implicit() { return true; }

  // One DLA step from (q_curr, p_curr).  q_guess and lambda (in) are the
  // starting iterate; on success q_next, lambda and p_next hold the solution.
  StepSummary step(const VecN& q_curr, const VecN& p_curr, const VecN& q_guess, VecN* q_next,
                   VecM* lambda, VecN* p_next) const {
    const Mat<double, mc, n> W = force_forms(q_curr);
    StepSummary s = newton(q_curr, p_curr, W, q_guess, *lambda, q_next, lambda);
    if (s.status != SolveStatus::kConverged && options_.fallback) {
      StepSummary f = tiny_solver(q_curr, p_curr, W, q_guess, *lambda, q_next, lambda);
      f.iterations += s.iterations;
      f.evaluations += s.evaluations;
      f.used_fallback = true;
      if (f.status != SolveStatus::kConverged)
        f.message = "Newton: " + s.message + "; TinySolver fallback: " + f.message;
      s = f;
    }
    if (s.status == SolveStatus::kConverged) {
      discrete_lagrangian_slots<S, D, double>(sys_, disc_, h_, q_curr, *q_next, nullptr, p_next);
      if (!p_next->allFinite()) {
        s.status = SolveStatus::kFailed;
        s.message = "non-finite momentum p_{k+1}";
      }
    }
    return s;
  }

  // Relative residual of eq. (6) at (q_next, lambda); *r_out gets the residual.
  double relative_residual(const VecN& q_curr, const VecN& p_curr, const VecN& q_next,
                           const VecM& lambda, VecX* r_out = nullptr) const {
    const Mat<double, mc, n> W = force_forms(q_curr);
    VecX r;
    Mat<double, N, n> Jq;
    const double rel = evaluate(q_curr, p_curr, W, q_next, lambda, &r, &Jq);
    if (r_out) *r_out = r;
    return rel;
  }

 private:
  // The one-forms the multipliers act on at q_k: omega(q_k) and, with holonomic
  // constraints, Dg(q_k) below it (eq. 17, first line).
  Mat<double, mc, n> force_forms(const VecN& q) const {
    Mat<double, mc, n> W;
    W.template topRows<m>() = sys_.template omega<double>(q);
    if constexpr (l > 0) W.template bottomRows<l>() = holonomic_jacobian(sys_, q);
    return W;
  }

  // r = (p_k + D1 L_d(q_k, q1) - W^T lambda, omega_d(q_k, q1) [, g(q1)]), W = force_forms(q_k);
  // *terms gets, per row, the sum of the magnitudes of the terms r_i adds up.
  template <class T>
  void residual(const VecN& q_curr, const VecN& p_curr, const Mat<double, mc, n>& W,
                const Vec<T, n>& q1, const Vec<T, mc>& lambda, Vec<T, N>* r,
                VecX* terms = nullptr) const {
    const Vec<T, n> q0 = q_curr.template cast<T>();
    Vec<T, n> D1;
    discrete_lagrangian_slots<S, D, T>(sys_, disc_, h_, q0, q1, &D1, nullptr);
    Vec<double, m> cscale;
    const Vec<T, m> wd = discrete_constraint<S, D, T>(sys_, disc_, h_, q0, q1, &cscale);
    for (int i = 0; i < n; ++i) {
      T force = cst<T>(0.0);
      double fscale = 0;
      for (int a = 0; a < mc; ++a) {
        force += cst<T>(W(a, i)) * lambda[a];
        fscale += std::abs(W(a, i) * value_of(lambda[a]));
      }
      (*r)[i] = cst<T>(p_curr[i]) + D1[i] - force;
      if (terms) (*terms)[i] = std::abs(p_curr[i]) + std::abs(value_of(D1[i])) + fscale;
    }
    for (int a = 0; a < m; ++a) {
      (*r)[n + a] = wd[a];
      if (terms) (*terms)[n + a] = cscale[a];
    }
    if constexpr (l > 0) {  // g(q_{k+1}) = 0 (eq. 17, second line); its scale comes from Dg
      const Vec<T, l> gv = sys_.template g<T>(q1);
      for (int a = 0; a < l; ++a) {
        (*r)[n + m + a] = gv[a];
        if (terms) (*terms)[n + m + a] = 0;
      }
    }
  }

  // Residual and its q1-Jacobian Jq by one Jet evaluation; returns the relative
  // residual max_i |r_i| / (terms_i + sum_j |Jq_ij| (|q_k,j| + |q1_j|)).  The
  // second part is the residual a relative perturbation of q of one unit causes,
  // so the floor it sets is round-off in the difference quotient (q1 - q0)/h,
  // which grows with |q| (a coordinate that has travelled far, like z).
  double evaluate(const VecN& q_curr, const VecN& p_curr, const Mat<double, mc, n>& W,
                  const VecN& q1, const VecM& lambda, VecX* r, Mat<double, N, n>* Jq) const {
    using J = ceres::Jet<double, n>;
    Vec<J, n> q1j;
    for (int i = 0; i < n; ++i) q1j[i] = J(q1[i], i);
    const Vec<J, mc> lj = lambda.template cast<J>();
    Vec<J, N> rj;
    VecX terms;
    residual<J>(q_curr, p_curr, W, q1j, lj, &rj, &terms);
    double rel = 0;
    for (int i = 0; i < N; ++i) {
      (*r)[i] = rj[i].a;
      double scale = terms[i];
      for (int j = 0; j < n; ++j) {
        (*Jq)(i, j) = rj[i].v[j];
        scale += std::abs(rj[i].v[j]) * (std::abs(q_curr[j]) + std::abs(q1[j]));
      }
      rel = std::max(rel, ratio((*r)[i], scale));
    }
    return rel;
  }

  // The residual alone (no derivatives), judged with the scale of a nearby
  // Jacobian Jq (the one the chord iterations use): cheap.
  double evaluate_value(const VecN& q_curr, const VecN& p_curr, const Mat<double, mc, n>& W,
                        const VecN& q1, const VecM& lambda, const Mat<double, N, n>& Jq,
                        VecX* r) const {
    VecX terms;
    residual<double>(q_curr, p_curr, W, q1, lambda, r, &terms);
    double rel = 0;
    for (int i = 0; i < N; ++i) {
      double scale = terms[i];
      for (int j = 0; j < n; ++j)
        scale += std::abs(Jq(i, j)) * (std::abs(q_curr[j]) + std::abs(q1[j]));
      rel = std::max(rel, ratio((*r)[i], scale));
    }
    return rel;
  }

  // Solves the linear system with the matrix (7), [A  -W^T; B  0], A = D2 D1 L_d,
  // B = D2 of (omega_d [, g]), W = force_forms(q_k).  While A is comfortably invertible (the usual
  // case: A ~ -M/h) by the Schur complement on the fixed-size A (Eigen's closed
  // forms for n <= 4), else by pivoted LU of the whole matrix.
  class StepSolver {
   public:
    explicit StepSolver(const Mat<double, mc, n>& W) : Wt_(W.transpose()) {}
    void factor(const Mat<double, N, n>& Jq) {
      const Mat<double, n, n> A = Jq.template topRows<n>();
      B_ = Jq.template bottomRows<mc>();
      bool invertible = false;
      if constexpr (n <= 4 && mc > 0) {
        // |det A| against the size of its entries, as det scales: relative 1e-10.
        A.computeInverseWithCheck(Ainv_, invertible, 1e-10 * std::pow(A.cwiseAbs().maxCoeff(), n));
      }
      if constexpr (mc > 0) {
        if (invertible) {
          const Mat<double, mc, mc> Sm = B_ * Ainv_ * Wt_;  // Schur complement B A^-1 W^T
          schur_.compute(Sm);
          schur_ok_ =
              std::isfinite(Sm.sum()) &&
              std::abs(schur_.determinant()) > 1e-10 * std::pow(Sm.cwiseAbs().maxCoeff(), mc);
        } else {
          schur_ok_ = false;
        }
      }
      if (!schur_ok_) {
        Mat<double, N, N> K = Mat<double, N, N>::Zero();
        K.template leftCols<n>() = Jq;
        K.template topRightCorner<n, mc>() = -Wt_;
        lu_.compute(K);
      }
    }
    VecX solve(const VecX& r) const {
      if constexpr (mc == 0) {
        return lu_.solve(r);
      } else {
        if (!schur_ok_) return lu_.solve(r);
        // A dq - W^T dl = r1,  B dq = r2  =>  (B A^-1 W^T) dl = r2 - B A^-1 r1.
        const VecN y = Ainv_ * r.template head<n>();
        const VecM dl = schur_.solve(VecM(r.template tail<mc>() - B_ * y));
        VecX dx;
        dx.template head<n>() = y + Ainv_ * (Wt_ * dl);
        dx.template tail<mc>() = dl;
        return dx;
      }
    }

   private:
    Mat<double, n, mc> Wt_;
    Mat<double, mc, n> B_;
    Mat<double, n, n> Ainv_;
    Eigen::PartialPivLU<Mat<double, mc, mc>> schur_;
    Eigen::PartialPivLU<Mat<double, N, N>> lu_;
    bool schur_ok_ = false;
  };

  static double ratio(double r, double scale) {
    if (!std::isfinite(r) || !std::isfinite(scale)) return std::numeric_limits<double>::infinity();
    if (r == 0) return 0;
    return std::abs(r) / std::max(scale, std::numeric_limits<double>::min());
  }

  StepSummary newton(const VecN& q_curr, const VecN& p_curr, const Mat<double, mc, n>& W,
                     const VecN& q_guess, const VecM& lambda_guess, VecN* q_out,
                     VecM* lambda_out) const {
    constexpr double kRoundoff = 16 * std::numeric_limits<double>::epsilon();
    StepSummary s;
    VecN q1 = q_guess;
    VecM lambda = lambda_guess;
    double prev = std::numeric_limits<double>::infinity();
    VecX r;
    Mat<double, N, n> Jq;
    StepSolver solver(W);
    // Newton with the Jacobian (7) refreshed only when the last step contracted
    // the residual by less than 1e-3 (otherwise the factorization is reused):
    // near round-off the converged iterate is the same, with fewer Jet passes.
    bool fresh = true;  // r, Jq were just evaluated with derivatives at the iterate
    double rel = evaluate(q_curr, p_curr, W, q1, lambda, &r, &Jq);
    ++s.evaluations;
    for (int it = 0;; ++it) {
      s.relative_residual = rel;
      if (!std::isfinite(rel)) {
        s.message = "non-finite residual";
        return s;
      }
      // Converged: within tolerance, and at round-off or no longer improving.
      if (rel <= options_.tolerance && (rel <= kRoundoff || rel > 0.5 * prev)) break;
      if (it == options_.max_iterations) {
        if (rel <= options_.tolerance) break;
        s.message = "no convergence in " + std::to_string(it) + " iterations (relative residual " +
                    std::to_string(rel) + ")";
        return s;
      }
      if (fresh) solver.factor(Jq);
      const VecX dx = solver.solve(r);
      if (!dx.allFinite()) {
        s.message = "singular step matrix (eq. 7)";
        return s;
      }
      q1 -= dx.template head<n>();
      lambda -= dx.template tail<mc>();
      prev = rel;
      ++s.iterations;
      rel = evaluate_value(q_curr, p_curr, W, q1, lambda, Jq, &r);
      ++s.evaluations;
      fresh = false;
      if (!(rel <= 1e-3 * prev) && !(rel <= kRoundoff)) {  // slow contraction: refresh the Jacobian
        rel = evaluate(q_curr, p_curr, W, q1, lambda, &r, &Jq);
        ++s.evaluations;
        fresh = true;
      }
    }
    *q_out = q1;
    *lambda_out = lambda;
    s.status = SolveStatus::kConverged;
    return s;
  }

  // The same residual for ceres::TinySolverAutoDiffFunction (all N unknowns).
  struct Functor {
    enum { NUM_RESIDUALS = N, NUM_PARAMETERS = N };
    const DlaStepper* self;
    const VecN* q_curr;
    const VecN* p_curr;
    const Mat<double, mc, n>* W;
    template <class T>
    bool operator()(const T* x, T* residuals) const {
      Vec<T, n> q1;
      Vec<T, mc> lambda;
      for (int i = 0; i < n; ++i) q1[i] = x[i];
      for (int a = 0; a < mc; ++a) lambda[a] = x[n + a];
      Vec<T, N> r;
      self->residual(*q_curr, *p_curr, *W, q1, lambda, &r);
      for (int i = 0; i < N; ++i) residuals[i] = r[i];
      return true;
    }
  };

  StepSummary tiny_solver(const VecN& q_curr, const VecN& p_curr, const Mat<double, mc, n>& W,
                          const VecN& q_guess, const VecM& lambda_guess, VecN* q_out,
                          VecM* lambda_out) const {
    StepSummary s;
    Functor f{this, &q_curr, &p_curr, &W};
    ceres::TinySolverAutoDiffFunction<Functor, N, N> cost(f);  // keeps a reference to f
    ceres::TinySolver<ceres::TinySolverAutoDiffFunction<Functor, N, N>> solver;
    solver.options.max_num_iterations = 200;
    solver.options.gradient_tolerance = 0;
    solver.options.parameter_tolerance = 1e-15;  // relative step below round-off: stop
    solver.options.function_tolerance = 0;       // (2.1: this one is absolute)
    solver.options.cost_threshold = 0;
    VecX x;
    x.template head<n>() = q_guess;
    x.template tail<mc>() = lambda_guess;
    const auto& summary = solver.Solve(cost, &x);
    s.iterations = summary.iterations;
    s.evaluations = summary.iterations + 1;
    const VecN q1 = x.template head<n>();
    const VecM lambda = x.template tail<mc>();
    VecX r;
    Mat<double, N, n> Jq;
    s.relative_residual = evaluate(q_curr, p_curr, W, q1, lambda, &r, &Jq);
    if (std::isfinite(s.relative_residual) && s.relative_residual <= options_.tolerance) {
      *q_out = q1;
      *lambda_out = lambda;
      s.status = SolveStatus::kConverged;
    } else {
      s.message = "relative residual " + std::to_string(s.relative_residual) + " after " +
                  std::to_string(summary.iterations) + " iterations";
    }
    return s;
  }

  S sys_;
  D disc_;
  double h_;
  DlaOptions options_;
};

}  // namespace nhi
