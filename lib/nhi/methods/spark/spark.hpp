// Lobatto IIIA-IIIB SPARK integrators for nonholonomic systems (L. O. Jay,
// "Lagrange-d'Alembert SPARK integrators for nonholonomic Lagrangian systems",
// 2009; the constraint's stage average from L. O. Jay, "Specialized
// partitioned additive Runge-Kutta methods for systems of overdetermined
// DAEs with holonomic constraints", BIT 43, 2003), in the form odelab
// implements (odelab/scheme/rungekutta.py, classes Spark2, Spark3, Spark4).
// With s stages, A = Lobatto IIIA, Ahat = Lobatto IIIB (the same b and c),
// V = dH/dp, F = -dH/dq (hamiltonian.hpp) and G(q, p) = omega(q) V(q, p), one
// step (q0, p0) -> (q1, p1) solves for the stages Q_i, P_i, the multipliers
// Lambda_i (i = 1..s) and p1:
//   (1) Q_i = q0 + h sum_j a_ij V(Q_j, P_j)                         (IIIA)
//   (2) P_i = p0 + h sum_j ahat_ij [F(Q_j, P_j) + omega(Q_j)^T Lambda_j]   (IIIB)
//   (3) q1 = q0 + h sum_j b_j V(Q_j, P_j)   (= Q_s: IIIA's last row is b)
//   (4) p1 = p0 + h sum_j b_j [F(Q_j, P_j) + omega(Q_j)^T Lambda_j]
//   (5) sum_j a_ij G(Q_j, P_j) = 0, i = 2..s: the stage values G_j lie on the
//       shifted Legendre polynomial P_{s-1}, G_j = pi_j G_s with
//       pi_j = P_{s-1}(2 c_j - 1), j = 1..s-1 (the same roots; better conditioned)
//   (6) G(q1, p1) = 0: the velocity constraint holds at every grid point.
// Q_1 = q0 (IIIA's first row is 0), so the unknowns are y = (Q_2..Q_s,
// P_1..P_s, p1, Lambda_1..Lambda_s), 2ns + ms of them, solved by Newton on
// the whole system (NewtonSolver with nl = 0).  Of order 2s - 2 in (q, p),
// symmetric and, on a reversible system, rho-reversible for consistent starts
// (asserted for every scene by the typed contract suite, tests/test_methods.cpp).  The multiplier
// reported is Lambda_s, which is only O(h^(s-1)) close to lambda(t1).
// s = 2 is a kick-drift-kick RATTLE-type method (P_1 = P_2), the counterpart
// of mp06's drift-kick-drift (mp06.hpp): a different map of the same order.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "nhi/methods/composition.hpp"
#include "nhi/methods/constraint_rows.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/solver/solver.hpp"

namespace nhi {

// Lobatto IIIA and IIIB with s stages (Hairer, Lubich & Wanner, Geometric
// Numerical Integration, 2nd ed., section II.2.2, Tables 2.1-2.3; Hairer &
// Wanner, Solving ODEs II, section IV.5), and pi_j = P_{s-1}(2 c_j - 1).
template <int s>
struct LobattoTableau {
  static_assert(s >= 2 && s <= 4, "SPARK is implemented for s = 2, 3, 4");
  std::array<std::array<double, s>, s> a{}, ahat{};
  std::array<double, s> b{}, c{}, pi{};

  static const LobattoTableau& get() {
    static const LobattoTableau t = make();
    return t;
  }

 private:
  static LobattoTableau make() {
    LobattoTableau t;
    if constexpr (s == 2) {
      t.c = {0.0, 1.0};
      t.b = {0.5, 0.5};
      t.a = {{{0.0, 0.0}, {0.5, 0.5}}};
      t.ahat = {{{0.5, 0.0}, {0.5, 0.0}}};
    } else if constexpr (s == 3) {
      t.c = {0.0, 0.5, 1.0};
      t.b = {1.0 / 6, 2.0 / 3, 1.0 / 6};
      t.a = {{{0.0, 0.0, 0.0}, {5.0 / 24, 1.0 / 3, -1.0 / 24}, {1.0 / 6, 2.0 / 3, 1.0 / 6}}};
      t.ahat = {{{1.0 / 6, -1.0 / 6, 0.0}, {1.0 / 6, 1.0 / 3, 0.0}, {1.0 / 6, 5.0 / 6, 0.0}}};
    } else {
      const double r5 = std::sqrt(5.0);
      t.c = {0.0, (5 - r5) / 10, (5 + r5) / 10, 1.0};
      t.b = {1.0 / 12, 5.0 / 12, 5.0 / 12, 1.0 / 12};
      t.a = {{{0.0, 0.0, 0.0, 0.0},
              {(11 + r5) / 120, (25 - r5) / 120, (25 - 13 * r5) / 120, (-1 + r5) / 120},
              {(11 - r5) / 120, (25 + 13 * r5) / 120, (25 + r5) / 120, (-1 - r5) / 120},
              {1.0 / 12, 5.0 / 12, 5.0 / 12, 1.0 / 12}}};
      t.ahat = {{{1.0 / 12, (-1 - r5) / 24, (-1 + r5) / 24, 0.0},
                 {1.0 / 12, (25 + r5) / 120, (25 - 13 * r5) / 120, 0.0},
                 {1.0 / 12, (25 + 13 * r5) / 120, (25 - r5) / 120, 0.0},
                 {1.0 / 12, (11 - r5) / 24, (11 + r5) / 24, 0.0}}};
    }
    for (int j = 0; j < s; ++j) {  // Legendre P_{s-1}(x), x = 2 c_j - 1
      const double x = 2 * t.c[j] - 1;
      t.pi[j] = s == 2 ? x : s == 3 ? 0.5 * (3 * x * x - 1) : 0.5 * (5 * x * x * x - 3 * x);
    }
    return t;
  }
};

template <class S, int s>
struct SparkProblem {
  static constexpr int n = S::n, m = S::m;
  // y = (Q_2..Q_s, P_1..P_s, p1, Lambda_1..Lambda_s)
  static constexpr int kQ = 0, kP = n * (s - 1), kP1 = kP + n * s, kL = kP1 + n;
  static constexpr int ny = kL + m * s, nl = 0;
  using VecN = Vec<double, n>;
  using Tab = LobattoTableau<s>;

  const S& sys;
  double h;
  VecN q0, p0;
  Mat<double, ny, nl> W_t;  // empty: the multipliers are part of y

  SparkProblem(const S& sy, double hh, const VecN& q, const VecN& p) : sys(sy), h(hh), q0(q), p0(p) {}

  const Mat<double, ny, nl>& Wt() const { return W_t; }

  // Root following (solver.hpp): the same step at h2; as h -> 0 every stage
  // tends to (q0, p0), the multipliers to that of a force.
  SparkProblem at_step(double h2) const { return SparkProblem(sys, h2, q0, p0); }
  void small_step_start(double ratio, Vec<double, ny>* y, Vec<double, nl>*) const {
    for (int i = 0; i < s - 1; ++i)
      y->template segment<n>(kQ + n * i) = q0 + ratio * (y->template segment<n>(kQ + n * i) - q0);
    for (int i = 0; i <= s; ++i)
      y->template segment<n>(kP + n * i) = p0 + ratio * (y->template segment<n>(kP + n * i) - p0);
  }

  Vec<double, ny> y_scale(const Vec<double, ny>& y) const {
    Vec<double, ny> sc = y.cwiseAbs();
    for (int i = 0; i < s - 1; ++i) sc.template segment<n>(kQ + n * i) += q0.cwiseAbs();
    for (int i = 0; i <= s; ++i) sc.template segment<n>(kP + n * i) += p0.cwiseAbs();
    return sc;
  }

  // Stage i's (Q_i, P_i) from y.
  template <class T>
  Vec<T, n> stage_q(const Vec<T, ny>& y, int i) const {
    return i == 0 ? Vec<T, n>(q0.template cast<T>()) : Vec<T, n>(y.template segment<n>(kQ + n * (i - 1)));
  }

  template <class T>
  void residual(const Vec<T, ny>& y, const Vec<T, nl>&, Vec<T, ny>* r, Vec<double, ny>* terms) const {
    const Tab& tb = Tab::get();
    std::array<Vec<T, n>, s> Vs, Fs;  // V(Q_j, P_j) and F(Q_j, P_j) + omega(Q_j)^T Lambda_j
    std::array<Vec<T, m>, s> Gs;
    std::array<VecN, s> vsz, fsz;  // their sizes, for the terms
    std::array<double, s> gsz{};
    for (int j = 0; j < s; ++j) {
      const Vec<T, n> Q = stage_q(y, j), P = y.template segment<n>(kP + n * j);
      const Vec<T, m> L = y.template segment<m>(kL + m * j);
      Vs[j] = velocity(sys, Q, P);
      Vec<T, n> F, dv;
      lagrangian_partials(sys, Q, Vs[j], &F, &dv);  // F = dL/dq(Q, V) = -dH/dq
      const Mat<T, m, n> W = sys.template omega<T>(Q);
      Fs[j] = F + W.transpose() * L;
      Gs[j] = W * Vs[j];
      for (int k = 0; k < n; ++k) {
        vsz[j][k] = std::abs(value_of(Vs[j][k]));
        double f = std::abs(value_of(F[k]));
        for (int a = 0; a < m; ++a) f += std::abs(value_of(W(a, k)) * value_of(L[a]));
        fsz[j][k] = f;
      }
      gsz[j] = 0;  // the largest row's terms |omega_ak V_k|
      for (int a = 0; a < m; ++a) {
        double g = 0;
        for (int k = 0; k < n; ++k) g += std::abs(value_of(W(a, k)) * value_of(Vs[j][k]));
        gsz[j] = std::max(gsz[j], g);
      }
    }
    // (1) for i = 2..s
    for (int i = 1; i < s; ++i)
      for (int k = 0; k < n; ++k) {
        T acc = cst<T>(0.0);
        double sz = 0;
        for (int j = 0; j < s; ++j) {
          acc += cst<T>(tb.a[i][j]) * Vs[j][k];
          sz += std::abs(tb.a[i][j]) * vsz[j][k];
        }
        const T Qik = y[kQ + n * (i - 1) + k];
        (*r)[kQ + n * (i - 1) + k] = Qik - cst<T>(q0[k]) - cst<T>(h) * acc;
        if (terms) (*terms)[kQ + n * (i - 1) + k] = std::abs(value_of(Qik)) + std::abs(q0[k]) + std::abs(h) * sz;
      }
    // (2) for i = 1..s, and (4) as row s
    for (int i = 0; i <= s; ++i)
      for (int k = 0; k < n; ++k) {
        T acc = cst<T>(0.0);
        double sz = 0;
        for (int j = 0; j < s; ++j) {
          const double c = i < s ? tb.ahat[i][j] : tb.b[j];
          acc += cst<T>(c) * Fs[j][k];
          sz += std::abs(c) * fsz[j][k];
        }
        const T Pik = y[kP + n * i + k];
        (*r)[kP + n * i + k] = Pik - cst<T>(p0[k]) - cst<T>(h) * acc;
        if (terms) (*terms)[kP + n * i + k] = std::abs(value_of(Pik)) + std::abs(p0[k]) + std::abs(h) * sz;
      }
    // (5) G_j - pi_j G_s = 0, j = 1..s-1
    for (int j = 0; j < s - 1; ++j)
      for (int a = 0; a < m; ++a) {
        (*r)[kL + m * j + a] = Gs[j][a] - cst<T>(tb.pi[j]) * Gs[s - 1][a];
        if (terms) (*terms)[kL + m * j + a] = gsz[j] + std::abs(tb.pi[j]) * gsz[s - 1];
      }
    // (6) omega(q1) V(q1, p1) = 0, q1 = Q_s
    const Vec<T, n> q1 = stage_q(y, s - 1), p1 = y.template segment<n>(kP1);
    const Vec<T, n> v1 = velocity(sys, q1, p1);
    const Mat<T, m, n> W1 = sys.template omega<T>(q1);
    velocity_constraint_rows(W1, v1, kL + m * (s - 1), r, terms);
  }

  // The residual's y-Jacobian, assembled from each stage's derivatives in its
  // own 2n + m unknowns (Q_j, P_j, Lambda_j): Jets of that width instead of
  // ny = 2ns + ms (NewtonSolver's has_jacobian).  Every entry is the sum the
  // Jet pass over all of y forms, term by term in the same order, so the two
  // agree to the last bit (tests/test_spark.cpp compares them).
  void jacobian(const Vec<double, ny>& y, const Vec<double, nl>&, Mat<double, ny, ny>* Jy) const {
    constexpr int nz = 2 * n + m;
    using J = ceres::Jet<double, nz>;
    using Dn = Mat<double, n, ny>;
    const Tab& tb = Tab::get();
    // Stage j's V, F + omega^T Lambda and G, and the end point's G(q1, p1),
    // differentiated in y: rows of width ny, zero outside the stage's columns.
    std::array<Dn, s> dV, dF;
    std::array<Mat<double, m, ny>, s + 1> dG;
    for (int j = 0; j <= s; ++j) {
      const bool end = j == s;  // (q1, p1) = (Q_s, y[kP1]), no multiplier
      const int jq = end ? s - 1 : j;
      // the columns of (Q, P, Lambda) in y; -1: a constant (Q_1 = q0; the end's Lambda)
      std::array<int, nz> col;
      for (int k = 0; k < n; ++k) {
        col[k] = jq == 0 ? -1 : kQ + n * (jq - 1) + k;
        col[n + k] = (end ? kP1 : kP + n * j) + k;
      }
      for (int a = 0; a < m; ++a) col[2 * n + a] = end ? -1 : kL + m * j + a;
      Vec<J, n> Q, P;
      Vec<J, m> L;
      for (int k = 0; k < n; ++k) {
        Q[k] = J(jq == 0 ? q0[k] : y[col[k]], k);
        P[k] = J(y[col[n + k]], n + k);
      }
      for (int a = 0; a < m; ++a) L[a] = J(end ? 0.0 : y[col[2 * n + a]], 2 * n + a);
      const Vec<J, n> V = velocity(sys, Q, P);
      const Mat<J, m, n> W = sys.template omega<J>(Q);
      Vec<J, m> G;
      if (end) {  // row (6)'s sum, as residual() forms it
        Vec<J, m> r6;
        velocity_constraint_rows<J, m, n, m>(W, V, 0, &r6, nullptr);
        G = r6;
      } else {
        G = W * V;
      }
      auto spread = [&](const auto& f, auto* d) {
        d->setZero();
        for (int r = 0; r < f.size(); ++r)
          for (int c = 0; c < nz; ++c)
            if (col[c] >= 0) (*d)(r, col[c]) = f[r].v[c];
      };
      spread(G, &dG[j]);
      if (end) continue;
      Vec<J, n> F, dv;
      lagrangian_partials(sys, Q, V, &F, &dv);
      const Vec<J, n> Fs = F + W.transpose() * L;
      spread(V, &dV[j]);
      spread(Fs, &dF[j]);
    }
    Jy->setZero();
    // (1): Q_i - q0 - h sum_j a_ij V_j, i = 2..s
    for (int i = 1; i < s; ++i) {
      Dn acc = Dn::Zero();
      for (int j = 0; j < s; ++j) acc += tb.a[i][j] * dV[j];
      Dn row = -h * acc;
      for (int k = 0; k < n; ++k) row(k, kQ + n * (i - 1) + k) = 1.0 - h * acc(k, kQ + n * (i - 1) + k);
      Jy->template block<n, ny>(kQ + n * (i - 1), 0) = row;
    }
    // (2) and (4): P_i - p0 - h sum_j ahat_ij (F + omega^T Lambda)_j
    for (int i = 0; i <= s; ++i) {
      Dn acc = Dn::Zero();
      for (int j = 0; j < s; ++j) acc += (i < s ? tb.ahat[i][j] : tb.b[j]) * dF[j];
      Dn row = -h * acc;
      for (int k = 0; k < n; ++k) row(k, kP + n * i + k) = 1.0 - h * acc(k, kP + n * i + k);
      Jy->template block<n, ny>(kP + n * i, 0) = row;
    }
    // (5): G_j - pi_j G_s
    for (int j = 0; j < s - 1; ++j) Jy->template block<m, ny>(kL + m * j, 0) = dG[j] - tb.pi[j] * dG[s - 1];
    // (6): G(q1, p1)
    Jy->template block<m, ny>(kL + m * (s - 1), 0) = dG[s];
  }

  // A first-order start: stage i at c_i h along the explicit step with the
  // given multipliers.
  Vec<double, ny> guess(const Vec<double, m * s>& lambda) const {
    const Tab& tb = Tab::get();
    const VecN v0 = velocity<S, double>(sys, q0, p0);
    VecN F0, dv;
    lagrangian_partials(sys, q0, v0, &F0, &dv);
    const Mat<double, m, n> W0 = sys.template omega<double>(q0);
    Vec<double, ny> y;
    for (int i = 1; i < s; ++i) y.template segment<n>(kQ + n * (i - 1)) = q0 + tb.c[i] * h * v0;
    for (int i = 0; i <= s; ++i) {
      const double c = i < s ? tb.c[i] : 1.0;
      const Vec<double, m> L = lambda.template segment<m>(m * (i < s ? i : s - 1));
      y.template segment<n>(kP + n * i) = p0 + c * h * (F0 + W0.transpose() * L);
    }
    y.template tail<m * s>() = lambda;
    return y;
  }
};

// The stateful SPARK stepper (stepper.hpp), lag 0.  The bodies of the
// members that solve (start, map, step, sample, phase) are in spark_body.hpp.
template <class S, int s>
class SparkStepper {
  static_assert(check_system<S>());  // a clear message for a type that is not a system (system.hpp)

 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  static constexpr int stages = s;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, m>;
  using VecML = Vec<double, m * s>;
  using Problem = SparkProblem<S, s>;

  explicit SparkStepper(const S& sys, SolverOptions options = {}) : sys_(sys), options_(options) {}
  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 2 * s - 2;
    t.symmetric = true;
    t.symmetric_in_phase = true;
    t.holds_velocity_constraint = true;
    t.implicit = true;
    return t;
  }

  // Start from p0 = dL/dqdot(q0, v0), the multipliers from 0.
  void start(const VecN& q0, const VecN& v0);

  // One step (q0, p0) -> (q1, p1); lambda holds the stages' guess and gets their multipliers.
  StepSummary map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1, VecML* lambda) const;

  StepSummary step(double h);

  // Point k: q_k, v_k = V(q_k, p_k) (omega(q_k) v_k = 0 to round-off), p_k,
  // Lambda_s of the step that arrived at k (0 at k = 0), and omega(q_k) v_k.
  void sample(Sample<n, m>* smp) const;

  Vec<double, 2 * n> phase() const;

 private:
  S sys_;
  SolverOptions options_;
  VecN q_ = VecN::Zero(), p_ = VecN::Zero();
  VecML lambda_ = VecML::Zero();
  long steps_ = 0;
};

// The method table's entry (methods.hpp): "spark" with MethodSpec::stages = 2, 3, 4.
struct SparkMethod {
  static constexpr const char* name = "spark";
  static constexpr bool adaptive = false;
  // Lobatto IIIA-IIIB stages s (order 2s - 2).
  static std::vector<MethodKey> keys() { return {MethodKey::integer("stages", &MethodSpec::stages, 2, 4)}; }
  static bool symmetric(const MethodSpec&) { return true; }  // so it composes (composition.hpp)
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 250.0;  // 25 (s = 2) to 1040 (s = 4) RK4 steps
  static std::string label(const MethodSpec& spec) { return std::string(name) + " s=" + std::to_string(spec.stages); }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    const SolverOptions opt = solver_options(spec);
    if (spec.stages == 3) return with_composition(SparkStepper<S, 3>(sys, opt), spec.composition, f);
    if (spec.stages == 4) return with_composition(SparkStepper<S, 4>(sys, opt), spec.composition, f);
    if (spec.stages != 2) throw std::invalid_argument("spark: stages must be 2, 3 or 4");
    return with_composition(SparkStepper<S, 2>(sys, opt), spec.composition, f);
  }
  static std::vector<StudyEntry> study_entries() {
    auto spark = [](int st, const char* group) {
      MethodSpec sp = spec_of(name);
      sp.stages = st;
      return StudyEntry{sp, group, 39 + st};  // line styles 41-43
    };
    // Newton on all 2ns + ms unknowns at once costs 25-1040 RK4 steps a step
    // (results/step_costs.json): the short-run studies only (methods.hpp).
    return {spark(2, "costly"), spark(3, "costly"), spark(4, "costly")};
  }
};

}  // namespace nhi
