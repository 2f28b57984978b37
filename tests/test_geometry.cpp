// The geometry of the discrete flow (paper section 5), checked on real runs.
//  - Theorem 5.3 (eq. 24), the discrete nonholonomic momentum equation, for the
//    particle with a potential in y only and for the robot with the planar
//    Euclidean group; its continuous counterpart (eq. 23) along the benchmark.
//  - Section 5.1: with no constraints the one-step map (q, p) -> (q', p') is
//    symplectic; with constraints it is not.
#include "nhi/methods/dla/dla_body.hpp"
#include "nhi/methods/reference/reference_body.hpp"
#include "nhi/systems/circle.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

template <class S, class D>
void dla_run(const S& sys, const D& disc, double h, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
             long steps, std::vector<Vec<double, S::n>>* qs, std::vector<Vec<double, S::n>>* ps) {
  const RunReport rep = integrate(DlaStepper<S, D>(sys, disc), q0, v0, h, steps, [&](const Sample<S::n, S::m>& s) {
    qs->push_back(s.q);
    ps->push_back(s.p);
    return true;
  });
  ASSERT_TRUE(rep.ok) << rep.reason;
}

// Particle, V = ky y^2 (kx = 0): translations in (x, z) leave L_d and omega_d
// invariant and the section xi(q) = (1, y) has generator d/dx + y d/dz in D.
// J_k = <D2 L_d(q_{k-1}, q_k), xi(q_k)_Q> = p_x + y_k p_z, and eq. (24) reads
//   J_{k+1} - J_k = p_{z,k+1} (y_{k+1} - y_k).
double particle_momentum_residual(double kx, double alpha) {
  Particle sys;
  sys.kx = kx;
  const Vec<double, 3> q0(1.0, 0.5, 0.0), v0(0.5, 1.0, 0.25);
  std::vector<Vec<double, 3>> qs, ps;
  dla_run(sys, AlphaDiscretization{alpha}, 0.2, q0, v0, 2000, &qs, &ps);
  double worst = 0;
  for (size_t k = 1; k + 1 < qs.size(); ++k) {
    const double Jk = Particle::nonholonomic_momentum(qs[k], ps[k]);
    const double Jk1 = Particle::nonholonomic_momentum(qs[k + 1], ps[k + 1]);
    const double rhs = Particle::momentum_equation_rhs(qs[k], qs[k + 1], ps[k + 1]);
    // The step equations are solved to round-off relative to their terms, which
    // include (q_{k+1} - q_k)/h: so is eq. (24), a combination of them.
    const double scale = std::abs(Jk) + std::abs(Jk1) + std::abs(rhs) + ps[k + 1].cwiseAbs().sum() +
                         (qs[k].cwiseAbs().maxCoeff() + qs[k + 1].cwiseAbs().maxCoeff()) / 0.2;
    worst = std::max(worst, std::abs(Jk1 - Jk - rhs) / scale);
  }
  return worst;
}

TEST(Theorem53, ParticleDiscreteMomentumEquationHolds) {
  for (double alpha : {0.5, 0.25}) {
    const double r = particle_momentum_residual(0.0, alpha);
    std::printf("    particle, V = y^2, alpha = %g: max relative residual of eq. (24) %.2e\n", alpha, r);
    EXPECT_LT(r, 1e-13) << "alpha " << alpha;
  }
  // With the paper's potential x^2 + y^2, x-translation is no symmetry: eq. (24)
  // must fail (the check can tell).
  EXPECT_GT(particle_momentum_residual(1.0, 0.5), 1e-4);
}

TEST(Theorem53, ParticleContinuousMomentumEquationAlongTheBenchmark) {
  // Eq. (23): d/dt (xd + y zd) = zd yd, by central differences of the benchmark.
  Particle sys;
  sys.kx = 0.0;
  const Vec<double, 3> q0(1.0, 0.5, 0.0), v0(0.5, 1.0, 0.25);
  const double dt = 1e-3;
  std::vector<double> J, rhs;
  ReferenceOptions bo;
  bo.rtol = bo.atol = 1e-13;
  integrate(ReferenceStepper<Particle>(sys, bo), q0, v0, dt, 20000, [&](const Sample<3, 1>& s) {
    J.push_back(s.v[0] + s.q[1] * s.v[2]);
    rhs.push_back(s.v[2] * s.v[1]);
    return true;
  });
  double worst = 0;
  for (size_t k = 1; k + 1 < J.size(); ++k)
    worst = std::max(worst, std::abs((J[k + 1] - J[k - 1]) / (2 * dt) - rhs[k]));
  std::printf("    particle benchmark: max |dJ/dt - zd yd| = %.2e (central differences, dt = 1e-3)\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// Robot, SE(2) acting on (x, y, theta): the section with generator d/dtheta is
// xi(q) = (1, (y, -x)) (rotation about the point (x, y)); xi(q_{k+1}) - xi(q_k)
// is the translation (dy, -dx), so eq. (24) reads
//   p_{theta,k+1} - p_{theta,k} = p_{x,k+1} (y_{k+1} - y_k) - p_{y,k+1} (x_{k+1} - x_k).
TEST(Theorem53, RobotDiscreteMomentumEquationHolds) {
  const Robot sys;
  const Vec<double, 4> q0(0.0, 0.0, 0.0, 0.0), v0(1.0, 0.0, 1.0, 1.0);
  for (double alpha : {0.5, 0.25}) {
    std::vector<Vec<double, 4>> qs, ps;
    dla_run(sys, AlphaDiscretization{alpha}, 0.2, q0, v0, 2000, &qs, &ps);
    double worst = 0, largest_rhs = 0;
    for (size_t k = 1; k + 1 < qs.size(); ++k) {
      const Vec<double, 4> d = qs[k + 1] - qs[k];
      const double rhs = Robot::momentum_equation_rhs(qs[k], qs[k + 1], ps[k + 1]);
      const double scale = std::abs(ps[k][2]) + std::abs(ps[k + 1][0] * d[1]) + std::abs(ps[k + 1][1] * d[0]);
      worst = std::max(worst, std::abs(Robot::nonholonomic_momentum(qs[k + 1], ps[k + 1]) -
                                       Robot::nonholonomic_momentum(qs[k], ps[k]) - rhs) /
                                  scale);
      largest_rhs = std::max(largest_rhs, std::abs(rhs));
    }
    std::printf("    robot, alpha = %g: max relative residual of eq. (24) %.2e (largest right-hand side %.2e)\n", alpha,
                worst, largest_rhs);
    EXPECT_LT(worst, 1e-12) << "alpha " << alpha;
  }
}

// The robot's Lagrangian with its constraints removed (n = 4, m = 0): a nonlinear
// unconstrained system for the symplecticity check.
struct FreeRobot {
  static constexpr int n = 4, m = 0;
  Robot r;
  template <class T>
  T lagrangian(const Vec<T, 4>& q, const Vec<T, 4>& v) const {
    return r.lagrangian<T>(q, v);
  }
  template <class T>
  Mat<T, 0, 4> omega(const Vec<T, 4>&) const {
    return Mat<T, 0, 4>();
  }
  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>&) const {
    return Vec<double, 4>(0, 0, 0, -r.V0 * std::cos(q[3]) / (3 * r.Iw));
  }
};

// Jacobian of the one-step map (q, p) -> (q', p') of the DLA (eq. 6 in
// position-momentum form) at a converged step, by the implicit function theorem
// on F(q, p, q', lambda) = (p + D1 L_d(q, q') - omega(q)^T lambda, omega_d(q, q')) = 0
// and p' = D2 L_d(q, q'), all derivatives from one Jet over (q, p, q', lambda).
//
// Eq. (22) in these coordinates: with p' dq' = d L_d + p dq - beta, where
// beta = lambda_a(q, p) omega^a(q) dq (the constraint force one-form, in D°),
//   phi^*(dq ^ dp) = dq ^ dp + d(beta),  i.e.  Dphi^T J Dphi - J = G^T - G,
// G the Jacobian of the coefficients b(q, p) = (omega(q)^T lambda(q, p), 0).
// *dbeta (optional) gets G^T - G.
template <class S, class D>
Eigen::MatrixXd step_map_jacobian(const S& sys, const D& disc, double h, const Vec<double, S::n>& q,
                                  const Vec<double, S::n>& p, const Vec<double, S::n>& q1,
                                  const Vec<double, S::m>& lambda, Eigen::MatrixXd* dbeta = nullptr) {
  constexpr int n = S::n, m = S::m, K = 3 * n + m;
  using J = ceres::Jet<double, K>;
  Vec<J, n> qj, pj, q1j;
  Vec<J, m> lj;
  for (int i = 0; i < n; ++i) {
    qj[i] = J(q[i], i);
    pj[i] = J(p[i], n + i);
    q1j[i] = J(q1[i], 2 * n + i);
  }
  for (int a = 0; a < m; ++a) lj[a] = J(lambda[a], 3 * n + a);
  Vec<J, n> D1, D2;
  discrete_lagrangian_slots<S, D, J>(sys, disc, h, qj, q1j, &D1, &D2);
  const Vec<J, m> wd = discrete_constraint<S, D, J>(sys, disc, h, qj, q1j);
  const Mat<J, m, n> W = sys.template omega<J>(qj);
  Eigen::MatrixXd Fx(n + m, 2 * n), Fy(n + m, n + m), Px(n, 2 * n), Py(n, n + m);
  Px.setZero();
  Py.setZero();
  for (int i = 0; i < n; ++i) {
    J Fi = pj[i] + D1[i];
    for (int a = 0; a < m; ++a) Fi = Fi - W(a, i) * lj[a];
    for (int c = 0; c < 2 * n; ++c) Fx(i, c) = Fi.v[c];
    for (int c = 0; c < n + m; ++c) Fy(i, c) = Fi.v[2 * n + c];
    for (int c = 0; c < 2 * n; ++c) Px(i, c) = D2[i].v[c];
    for (int c = 0; c < n; ++c) Py(i, c) = D2[i].v[2 * n + c];
  }
  for (int a = 0; a < m; ++a) {
    for (int c = 0; c < 2 * n; ++c) Fx(n + a, c) = wd[a].v[c];
    for (int c = 0; c < n + m; ++c) Fy(n + a, c) = wd[a].v[2 * n + c];
  }
  const Eigen::MatrixXd dy = -Fy.fullPivLu().solve(Fx);  // d(q', lambda)/d(q, p)
  Eigen::MatrixXd Dphi(2 * n, 2 * n);
  Dphi.topRows(n) = dy.topRows(n);
  Dphi.bottomRows(n) = Px + Py * dy;
  if (dbeta) {
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(2 * n, 2 * n);  // G(i, c) = d b_i / d x_c
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 2 * n; ++c)
        for (int a = 0; a < m; ++a) G(i, c) += (c < n ? W(a, i).v[c] * lambda[a] : 0.0) + W(a, i).a * dy(n + a, c);
    *dbeta = G.transpose() - G;
  }
  return Dphi;
}

inline double max_abs(const Eigen::MatrixXd& a) { return a.cwiseAbs().maxCoeff(); }

// The canonical form dq ^ dp as a matrix: u^T Jm w.
inline Eigen::MatrixXd canonical_form(int n) {
  Eigen::MatrixXd Jm = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  Jm.topRightCorner(n, n) = Eigen::MatrixXd::Identity(n, n);
  Jm.bottomLeftCorner(n, n) = -Eigen::MatrixXd::Identity(n, n);
  return Jm;
}

// Along `steps` DLA steps from (q, v): the largest relative symplectic defect
// |Dphi^T J Dphi - J| / (1 + |Dphi|^2), the largest relative distance of that
// defect from d(beta_d) (eq. 22), and the smallest defect seen.
struct FormWalk {
  double defect = 0, eq22 = 0, smallest_defect = 1e300;
};
template <class S, class D>
FormWalk walk_form(const S& sys, const D& disc, double h, Vec<double, S::n> q, Vec<double, S::n> v, int steps) {
  constexpr int n = S::n, m = S::m;
  const DlaMap<S, D> st(sys, disc, h);
  Vec<double, n> p = momentum(sys, q, v), q1, p1, guess = q + h * v;
  Vec<double, m> lambda = Vec<double, m>::Zero();
  const Eigen::MatrixXd Jm = canonical_form(n);
  Eigen::MatrixXd dbeta;
  FormWalk w;
  for (int k = 0; k < steps; ++k) {
    EXPECT_EQ(st.step(q, p, guess, &q1, &lambda, &p1).status, SolveStatus::kConverged);
    const Eigen::MatrixXd Dphi = step_map_jacobian(sys, disc, h, q, p, q1, lambda, &dbeta);
    const Eigen::MatrixXd defect = Dphi.transpose() * Jm * Dphi - Jm;
    const double size = 1.0 + max_abs(Dphi) * max_abs(Dphi);
    w.defect = std::max(w.defect, max_abs(defect) / size);
    w.eq22 = std::max(w.eq22, max_abs(defect - dbeta) / size);
    w.smallest_defect = std::min(w.smallest_defect, max_abs(defect));
    guess = q1 + (q1 - q);
    q = q1;
    p = p1;
  }
  return w;
}

template <class S, class D>
double symplectic_defect(const S& sys, const D& disc, double h, Vec<double, S::n> q, Vec<double, S::n> v) {
  return walk_form(sys, disc, h, q, v, 50).defect;
}

TEST(Symplecticity, UnconstrainedDlaMapIsSymplectic) {
  const FreeRobot sys;
  for (double alpha : {0.5, 0.0, 0.3}) {
    const double d = symplectic_defect(sys, AlphaDiscretization{alpha}, 0.2, Vec<double, 4>(0.1, 0.2, 0.3, 0.4),
                                       Vec<double, 4>(1.0, -0.5, 0.7, 1.3));
    std::printf("    no constraints, alpha = %g: max |Dphi^T J Dphi - J| (relative) = %.2e\n", alpha, d);
    EXPECT_LT(d, 1e-13);
  }
  const double s = symplectic_defect(sys, SymmetricDiscretization{0.25}, 0.2, Vec<double, 4>(0.1, 0.2, 0.3, 0.4),
                                     Vec<double, 4>(1.0, -0.5, 0.7, 1.3));
  EXPECT_LT(s, 1e-13);
}

TEST(Symplecticity, ConstrainedDlaMapIsNot) {
  // Eq. (22): with constraints the discrete form evolves by d(beta_d) != 0.
  const Robot sys;
  const double d =
      symplectic_defect(sys, AlphaDiscretization{0.5}, 0.2, Vec<double, 4>(0, 0, 0, 0), Vec<double, 4>(1, 0, 1, 1));
  std::printf("    robot with constraints: symplectic defect %.2e\n", d);
  EXPECT_GT(d, 1e-3);
}

// Eq. (22) itself: the defect Dphi^T J Dphi - J is exactly d(beta_d), the
// exterior derivative of the constraint-force one-form of the step, to round-off.
template <class S, class D>
void check_eq22(const S& sys, const D& disc, double h, Vec<double, S::n> q, Vec<double, S::n> v) {
  const FormWalk w = walk_form(sys, disc, h, q, v, 100);
  std::printf("    %s, %s: max |Dphi^T J Dphi - J - d(beta_d)| (relative) = %.2e; the defect itself >= %.2e\n", S::name,
              disc.name().c_str(), w.eq22, w.smallest_defect);
  EXPECT_LT(w.eq22, 1e-13);
  EXPECT_GT(w.smallest_defect, 1e-3);  // and the defect is really there
}

TEST(Symplecticity, DefectIsTheExteriorDerivativeOfTheConstraintForce) {
  const Particle particle;
  const Robot robot;
  for (double alpha : {0.5, 0.25}) {
    check_eq22(particle, AlphaDiscretization{alpha}, 0.2, Vec<double, 3>(1.0, 0.5, 0.0),
               Vec<double, 3>(0.5, 1.0, 0.25));
    check_eq22(robot, AlphaDiscretization{alpha}, 0.2, Vec<double, 4>(0, 0, 0, 0), Vec<double, 4>(1, 0, 1, 1));
  }
  check_eq22(robot, SymmetricDiscretization{0.25}, 0.2, Vec<double, 4>(0, 0, 0, 0), Vec<double, 4>(1, 0, 1, 1));
}

// Removing the constraints' non-integrability: the particle with
// omega_eps = dz - eps y dx.  The DLA maps T*Q onto the (2n - m)-dimensional
// set M_d = {(q', D2 L_d(q, q')) : omega_d(q, q') = 0}, and on T*Q the defect
// never vanishes (the multiplier absorbs p_z).  On M_d it does when eps = 0
// (dz: z = const, a holonomic constraint, and the DLA is the variational
// integrator on the leaf, Remark 3.3), and it grows with eps:
// the form restricted to M_d, pulled back by one step, against itself.
struct EpsParticle {
  static constexpr int n = 3, m = 1;
  double eps = 1.0;
  Particle base;
  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    return base.lagrangian<T>(q, v);
  }
  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    Mat<T, 1, 3> w;
    w << -cst<T>(eps) * q[1], cst<T>(0.0), cst<T>(1.0);
    return w;
  }
};

double restricted_defect(double eps) {
  EpsParticle sys;
  sys.eps = eps;
  constexpr int n = 3;
  const double h = 0.2;
  const AlphaDiscretization disc{0.5};
  const DlaMap<EpsParticle, AlphaDiscretization> st(sys, disc, h);
  Vec<double, n> q(1.0, 0.5, 0.0), v(0.5, 1.0, 0.25 * eps), q1 = q, p1 = q, guess = q + h * v;
  Vec<double, n> p = momentum(sys, q, v);
  Vec<double, 1> lambda = Vec<double, 1>::Zero();
  const Eigen::MatrixXd Jm = canonical_form(n);
  Eigen::MatrixXd prev;  // Dphi of the previous step: its range is T M_d at the current point
  double worst = 0;
  for (int k = 0; k < 60; ++k) {
    EXPECT_EQ(st.step(q, p, guess, &q1, &lambda, &p1).status, SolveStatus::kConverged);
    const Eigen::MatrixXd Dphi = step_map_jacobian(sys, disc, h, q, p, q1, lambda);
    if (k > 0) {
      Eigen::JacobiSVD<Eigen::MatrixXd> svd(prev, Eigen::ComputeFullU);
      const Eigen::MatrixXd T = svd.matrixU().leftCols(2 * n - 1);  // range of prev: T M_d
      const Eigen::MatrixXd d = T.transpose() * (Dphi.transpose() * Jm * Dphi - Jm) * T;
      const double size = max_abs(Dphi);
      worst = std::max(worst, max_abs(d) / (1.0 + size * size));
    }
    prev = Dphi;
    guess = q1 + (q1 - q);
    q = q1;
    p = p1;
  }
  return worst;
}

TEST(Symplecticity, DefectOnTheDiscreteConstraintSetShrinksAsTheConstraintBecomesIntegrable) {
  std::vector<double> eps{1.0, 0.1, 0.01, 0.001}, defects;
  for (double e : eps) defects.push_back(restricted_defect(e));
  const double zero = restricted_defect(0.0);
  std::printf("    restricted defect at eps = 1, 0.1, 0.01, 0.001, 0: %.2e %.2e %.2e %.2e %.2e (slope %.2f)\n",
              defects[0], defects[1], defects[2], defects[3], zero, loglog_slope(eps, defects));
  EXPECT_LT(zero, 1e-13);
  for (size_t i = 1; i < eps.size(); ++i) EXPECT_LT(defects[i], defects[i - 1]);
  EXPECT_NEAR(loglog_slope(eps, defects), 1.0, 0.1);  // O(eps): d(omega_eps) = eps dx ^ dy
  EXPECT_GT(defects[0], 1e-3);
}

// Corollary 5.4 needs a constant Lie-algebra element whose generator lies in D
// everywhere.  Neither paper scene has one (the particle's section (1, y) and the
// robot's d/dtheta section depend on q), so: the particle plus the smallest
// addition that has one, a coordinate u kinetically coupled to y,
//   L = 1/2 (xd^2 + yd^2 + zd^2 + ud^2) + eps ud yd - (x^2 + y^2),  zd - y xd = 0.
// Translations in u leave L and D invariant and d/du is in D (omega has no u
// column), so J = dL/dud = ud + eps yd is conserved, and its discrete version
// <D2 L_d, d/du> = p_u exactly.
struct CoupledParticle {
  static constexpr int n = 4, m = 1;
  double eps = 0.6;
  template <class T>
  T lagrangian(const Vec<T, 4>& q, const Vec<T, 4>& v) const {
    return cst<T>(0.5) * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) + cst<T>(eps) * v[3] * v[1] -
           (q[0] * q[0] + q[1] * q[1]);
  }
  template <class T>
  Mat<T, 1, 4> omega(const Vec<T, 4>& q) const {
    Mat<T, 1, 4> w;
    w << -q[1], cst<T>(0.0), cst<T>(1.0), cst<T>(0.0);
    return w;
  }
  Vec<double, 4> acceleration(const Vec<double, 4>& q, const Vec<double, 4>& v) const {
    return generic_acceleration(*this, q, v);
  }
};

TEST(Corollary54, HorizontalSymmetryMomentumIsConservedExactly) {
  const CoupledParticle sys;
  const Vec<double, 4> q0(1.0, 0.5, 0.0, 0.0), v0(0.5, 1.0, 0.25, -0.3);
  for (double alpha : {0.5, 0.25}) {
    std::vector<Vec<double, 4>> qs, ps;
    dla_run(sys, AlphaDiscretization{alpha}, 0.2, q0, v0, 5000, &qs, &ps);
    // Per step, p_u is conserved to round-off of the difference quotients it is
    // made of (|q|/h, u grows linearly); the total drift is their sum.
    double worst_step = 0, drift = 0, yd_range = 0;
    for (size_t k = 0; k < ps.size(); ++k) {
      if (k > 0) {
        const double floor = std::numeric_limits<double>::epsilon() *
                             (qs[k].cwiseAbs().maxCoeff() + qs[k - 1].cwiseAbs().maxCoeff()) / 0.2;
        worst_step = std::max(worst_step, std::abs(ps[k][3] - ps[k - 1][3]) / floor);
      }
      drift = std::max(drift, std::abs(ps[k][3] - ps[0][3]));
      yd_range = std::max(yd_range, std::abs(ps[k][1] - ps[0][1]));
    }
    std::printf(
        "    coupled particle, alpha = %g: max per-step |dp_u| = %.1f x eps |q|/h; total drift %.2e over 5000 steps "
        "(p_y varies by %.2f)\n",
        alpha, worst_step, drift, yd_range);
    EXPECT_LT(worst_step, 64.0);
    EXPECT_GT(yd_range, 0.1);  // the coupling is exercised
  }
  // Continuous: ud + eps yd is constant along the benchmark.
  double worst = 0;
  integrate(ReferenceStepper<decltype(sys)>(sys), q0, v0, 0.1, 500, [&](const Sample<4, 1>& s) {
    worst = std::max(worst, std::abs(s.v[3] + sys.eps * s.v[1] - (v0[3] + sys.eps * v0[1])));
    return true;
  });
  EXPECT_LT(worst, 1e-9);
}

// Remark 3.3: an integrable distribution.  A particle on the unit circle in the
// plane, L = 1/2 |v|^2 - g y, omega = q^T (so D = ker dG, G = |q|^2 / 2).  The
// midpoint discrete constraint is omega(q_mid) (q1 - q0)/h = (|q1|^2 - |q0|^2)/(2h),
// and omega(q_k)^T lambda = lambda DG(q_k): the midpoint DLA is the SHAKE-type
// variational integrator  D1 L_d + D2 L_d = lambda DG(q_k),  G(q_{k+1}) = G(q_0),
// which we solve here separately, with its own Newton, and compare.
TEST(Remark33, MidpointDlaIsShakeOnTheCircle) {
  const CircleParticle sys;
  const double h = 0.1;
  const Vec<double, 2> q0(std::cos(-0.3), std::sin(-0.3)), v0 = 1.7 * Vec<double, 2>(-q0[1], q0[0]);
  std::vector<Vec<double, 2>> qs, ps;
  dla_run(sys, AlphaDiscretization{0.5}, h, q0, v0, 5000, &qs, &ps);
  // SHAKE: unknowns (q1, lambda); p_k + D1 L_d(q_k, q1) - lambda q_k = 0, |q1|^2 = |q_k|^2;
  // p_{k+1} = D2 L_d(q_k, q1).  D1 L_d = -h g/2 e_y - (q1 - q_k)/h for the midpoint L_d.
  // One SHAKE step from each DLA state (q_k, p_k) must give the DLA's q_{k+1}, p_{k+1}.
  double worst = 0, worst_energy = 0;
  const double E0 = energy(sys, q0, v0);
  for (size_t k = 0; k + 1 < qs.size(); ++k) {
    const Vec<double, 2> q = qs[k], p = ps[k];
    Eigen::Vector3d x(qs[k + 1][0], qs[k + 1][1], 0.0);
    x.head<2>() = q + h * p;  // SHAKE's own first guess
    for (int it = 0; it < 30; ++it) {
      const Eigen::Vector2d q1 = x.head<2>();
      Eigen::Vector3d r;
      r.head<2>() = p - (q1 - q) / h - Eigen::Vector2d(0.0, 0.5 * h * sys.gravity) - x[2] * q;
      r[2] = 0.5 * (q1.squaredNorm() - q.squaredNorm());  // same level set as q_k (D_d of Remark 3.3)
      Eigen::Matrix3d J;
      J << -1 / h, 0, -q[0], 0, -1 / h, -q[1], q1[0], q1[1], 0;
      const Eigen::Vector3d dx = J.fullPivLu().solve(r);
      x -= dx;
      if (dx.cwiseAbs().maxCoeff() < 1e-16 * (1 + x.cwiseAbs().maxCoeff())) break;
    }
    const Eigen::Vector2d q1 = x.head<2>();
    const Eigen::Vector2d p1 = (q1 - q) / h - Eigen::Vector2d(0.0, 0.5 * h * sys.gravity);
    worst =
        std::max(worst, std::max((q1 - qs[k + 1]).cwiseAbs().maxCoeff(), h * (p1 - ps[k + 1]).cwiseAbs().maxCoeff()));
    if (k >= 1) {
      const Vec<double, 2> v = (qs[k + 1] - qs[k - 1]) / (2 * h);
      worst_energy = std::max(worst_energy, std::abs(energy(sys, qs[k], v) - E0));
    }
  }
  double radius_drift = 0;
  for (const auto& qk : qs) radius_drift = std::max(radius_drift, std::abs(qk.norm() - 1.0));
  std::printf(
      "    circle: max one-step |q_DLA - q_SHAKE|, h |p_DLA - p_SHAKE| = %.2e; max ||q| - 1| = %.2e over 5000 steps; "
      "max |E - E0| = %.2e\n",
      worst, radius_drift, worst_energy);
  EXPECT_LT(worst, 64 * std::numeric_limits<double>::epsilon());
  EXPECT_LT(radius_drift, 1e-11);  // round-off random walk of a conserved |q|
  EXPECT_LT(worst_energy, 0.05);   // bounded, O(h^2)
}

// The same circle in the Constrained Coordinate Formulation (eq. 17): its force
// row Dg(q_k) = q_k^T is the omega row and g(q_{k+1}) = 0 is the midpoint
// omega_d = 0 on the unit circle, so the eq.-17 step must give the omega-DLA step.
TEST(Remark33, HolonomicFormulationGivesTheSameStep) {
  const double h = 0.1;
  const Vec<double, 2> q0(std::cos(-0.3), std::sin(-0.3)), v0 = 1.7 * Vec<double, 2>(-q0[1], q0[0]);
  std::vector<Vec<double, 2>> qa, pa, qb, pb;
  dla_run(CircleParticle{}, AlphaDiscretization{0.5}, h, q0, v0, 5000, &qa, &pa);
  // One eq.-17 step from each state of the omega run.  The omega step keeps
  // |q_{k+1}| = |q_k|, the g step |q_{k+1}| = 1: they differ by the radius's
  // round-off drift ||q_k| - 1| (3e-12 here) and by the solver's round-off.
  const DlaMap<CircleHolonomic, AlphaDiscretization> st(CircleHolonomic{}, AlphaDiscretization{0.5}, h);
  double worst = 0, radius = 0;
  for (size_t k = 0; k + 1 < qa.size(); ++k) {
    Vec<double, 2> q1, p1;
    Vec<double, 1> lam = Vec<double, 1>::Zero();
    ASSERT_EQ(st.step(qa[k], pa[k], qa[k] + h * pa[k], &q1, &lam, &p1).status, SolveStatus::kConverged);
    radius = std::max(radius, std::abs(qa[k].norm() - 1.0));
    worst =
        std::max(worst, std::max((q1 - qa[k + 1]).cwiseAbs().maxCoeff(), h * (p1 - pa[k + 1]).cwiseAbs().maxCoeff()));
  }
  // The whole run in the g formulation, for the record (round-off differences
  // become a phase difference that grows along the run).
  dla_run(CircleHolonomic{}, AlphaDiscretization{0.5}, h, q0, v0, 5000, &qb, &pb);
  double run = 0;
  for (size_t k = 0; k < qa.size(); ++k) run = std::max(run, (qa[k] - qb[k]).cwiseAbs().maxCoeff());
  std::printf(
      "    circle: one eq.-17 step vs the omega-DLA step: max difference %.2e (radius drift %.2e); whole runs differ "
      "by %.2e after 5000 steps\n",
      worst, radius, run);
  EXPECT_LT(worst, 4 * radius + 64 * std::numeric_limits<double>::epsilon());
  EXPECT_LT(run, 1e-7);
}

}  // namespace
}  // namespace nhi::test
