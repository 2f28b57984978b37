// The discrete Euler-Poincare-Suslov step with the Cayley retraction
// (methods/group/eps_cayley.hpp) on the Suslov problem: its residual's
// Jacobian is the residual's derivative; it reproduces the steady rotation
// (suslov_steady.json) and the Fedorov-Zenkov turnover (suslov.json) with its
// declared order 2; it holds <a, Omega_k> = 0 and <a, y_k> = 0 and |p| = 1
// to round-off; its energy is exact on the steady rotations and returns
// after the turnover; it is self-adjoint and rho-reversible in (q, v); and,
// the claim to measure, its discrete flow on suslov.json travels to the steady
// rotation +c e1 at a rate kappa_h that tends to the continuous kappa as h^2
// (the group DLA and the embedded midpoint DLA measured beside it).
#include <cmath>

#include "nhi/methods/group/eps_cayley_body.hpp"
#include "nhi/methods/reference/reference.hpp"
#include "nhi/runner/scene.hpp"
#include "scenes.hpp"

namespace nhi::test {
namespace {

namespace qn = nhi::quaternion;
using Vec3 = Vec<double, 3>;
using Vec4 = Vec<double, 4>;
constexpr double kEps = std::numeric_limits<double>::epsilon();

static_assert(EpsCayleyMethod::studied_on<Suslov>());
static_assert(!EpsCayleyMethod::studied_on<ChaplyginSphere>());
static_assert(!EpsCayleyMethod::studied_on<Sleigh>());

Vec3 body_rate(const Vec4& q, const Vec4& v) { return 2.0 * qn::G<double>(q, v) / q.squaredNorm(); }

// A Suslov scene file (experiments/scenes/): the system, its state and its h.
struct FzScene {
  Suslov sys;
  Vec4 q0, v0;
  double h = 0, T = 0;
};
FzScene scene_file(const std::string& file) {
  const json sc = validate_scene(load_scene_file(std::string(NHI_SCENES) + "/" + file));
  FzScene f;
  f.sys.I1 = sc["params"]["I1"], f.sys.I2 = sc["params"]["I2"], f.sys.I3 = sc["params"]["I3"];
  f.sys.a1 = sc["params"]["a1"], f.sys.a2 = sc["params"]["a2"], f.sys.a3 = sc["params"]["a3"];
  for (int i = 0; i < 4; ++i) f.q0[i] = sc["q0"][i], f.v0[i] = sc["v0"][i];
  f.h = sc["h"];
  f.T = f.h * sc["steps"].get<double>();
  return f;
}

std::vector<Sample<4, 2>> run_eps(const Suslov& sys, const Vec4& q0, const Vec4& v0, double h, long steps) {
  std::vector<Sample<4, 2>> out;
  const RunReport rep = integrate(EpsCayleyStepper<Suslov>(sys), q0, v0, h, steps, [&](const Sample<4, 2>& s) {
    out.push_back(s);
    return true;
  });
  EXPECT_TRUE(rep.ok) << rep.reason;
  return out;
}

// The closed-form Jacobian of (DEPS) against central differences of the residual.
TEST(EpsCayley, JacobianIsTheResidualsDerivative) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Vec3 J(0.5 + std::abs(u(rng)), 2 + u(rng), 5 + 3 * u(rng)), a(u(rng), u(rng), u(rng)), M(u(rng), u(rng), u(rng));
    const EpsCayleyStepProblem p(J, a, M, 0.1 + 0.2 * std::abs(u(rng)));
    const Vec3 y(u(rng), u(rng), u(rng));
    const Vec<double, 1> lambda(u(rng));
    Mat<double, 4, 3> Jy, Jn;
    p.jacobian(y, lambda, &Jy);
    const double d = 1e-6;
    for (int j = 0; j < 3; ++j) {
      Vec<double, 4> rp, rm;
      Vec3 yp = y, ym = y;
      yp[j] += d, ym[j] -= d;
      p.residual<double>(yp, lambda, &rp, nullptr);
      p.residual<double>(ym, lambda, &rm, nullptr);
      Jn.col(j) = (rp - rm) / (2 * d);
    }
    EXPECT_LT((Jy - Jn).cwiseAbs().maxCoeff(), 1e-7 * (1 + Jy.cwiseAbs().maxCoeff())) << "trial " << trial;
  }
}

// suslov_steady.json (a = e3, principal): every motion is a steady rotation, and so
// is the discrete one: y_k = y_0 solves (DEPS) at every step (y^ J y is along
// a), so Omega_k = Omega_0 and the energy is exact; the rotation's phase is
// of order 2 (2 atan(|y|/2) per step against h |Omega|).
TEST(EpsCayley, SuslovSteadyRotationAtOrderTwo) {
  const FzScene sc = scene_file("suslov_steady.json");
  const Suslov& sys = sc.sys;
  const Vec4 q0 = sc.q0, v0 = sc.v0;
  const double T = 4, E0 = energy(sys, q0, v0);
  std::vector<double> hs, errs;
  for (double h : {0.1, 0.05, 0.025, 0.0125}) {
    const auto s = run_eps(sys, q0, v0, h, std::lround(T / h));
    Vec4 q, v;
    ASSERT_TRUE(sys.exact_solution(q0, v0, s.back().t, &q, &v));
    double dOm = 0, dE = 0;
    for (const auto& x : s) {
      dOm = std::max(dOm, (body_rate(x.q, x.v) - body_rate(q0, v0)).cwiseAbs().maxCoeff());
      dE = std::max(dE, std::abs(energy(sys, x.q, x.v) - E0));
    }
    hs.push_back(h);
    errs.push_back((s.back().q - q).cwiseAbs().maxCoeff());
    std::printf("    h = %-7g |q(T) - q_exact(T)| = %.3e, max |Omega_k - Omega_0| = %.1e, max |E - E0| = %.1e\n", h,
                errs.back(), dOm, dE);
    // To the step solve's tolerance (the solver stops within it of y_0).
    EXPECT_LT(dOm, 10 * kDefaultTolerance * (1 + body_rate(q0, v0).norm()));
    EXPECT_LT(dE, 10 * kDefaultTolerance * E0);
  }
  const OrderFit f = fit_order(hs, errs, 1e-12);
  ASSERT_TRUE(f.order);
  std::printf("    fitted order %.3f\n", *f.order);
  EXPECT_NEAR(*f.order, 2.0, 0.1);
}

// suslov.json (a not principal): q(T), Omega(T) against the reference
// solution (tol 1e-13) over T = 8, through the turnover near t* = 1.02.
TEST(EpsCayley, FedorovZenkovTurnoverAtOrderTwo) {
  const FzScene f = scene_file("suslov.json");
  const double T = 8;
  Vec4 qr, vr;
  reference_solution(f.sys, f.q0, f.v0, T, 1e-13, &qr, &vr);
  std::vector<double> hs, eq, eOm;
  for (double h : {0.08, 0.04, 0.02, 0.01, 0.005}) {
    const auto s = run_eps(f.sys, f.q0, f.v0, h, std::lround(T / h));
    hs.push_back(h);
    eq.push_back((s.back().q - qr).cwiseAbs().maxCoeff());
    eOm.push_back((body_rate(s.back().q, s.back().v) - body_rate(qr, vr)).cwiseAbs().maxCoeff());
    std::printf("    h = %-7g |q(T) - q_ref| = %.3e, |Omega(T) - Omega_ref| = %.3e\n", h, eq.back(), eOm.back());
  }
  const OrderFit fq = fit_order(hs, eq, 1e-10, 3, true), fO = fit_order(hs, eOm, 1e-10, 3, true);
  ASSERT_TRUE(fq.order && fO.order);
  std::printf("    fitted order: q %.3f, Omega %.3f\n", *fq.order, *fO.order);
  EXPECT_NEAR(*fq.order, 2.0, 0.1);
  EXPECT_NEAR(*fO.order, 2.0, 0.1);
}

// On the group and on the constraint: ||p| - 1|, <a, Omega_k> (the reported
// velocity) and <a, y_k>/h (the discrete constraint) at round-off over 10^4
// steps of suslov.json's h, and the norm row of the velocity too.
TEST(EpsCayley, StaysOnTheGroupAndHoldsTheConstraint) {
  const FzScene f = scene_file("suslov.json");
  const auto s = run_eps(f.sys, f.q0, f.v0, f.h, 10000);
  const Vec3 a = f.sys.suslov_axis();
  double norm = 0, aOm = 0, ay = 0, row0 = 0, Om = 0;
  for (const auto& x : s) {
    norm = std::max(norm, std::abs(x.q.norm() - 1));
    if (x.k == 0) continue;  // (the given v_0)
    const Vec3 w = body_rate(x.q, x.v);
    aOm = std::max(aOm, std::abs(a.dot(w)));
    Om = std::max(Om, w.cwiseAbs().maxCoeff());
    ay = std::max(ay, std::abs(x.discrete_constraint[1]));
    row0 = std::max(row0, std::abs(x.q.dot(x.v)));
  }
  std::printf("    max ||p| - 1| %.1e, |<a, Omega_k>| %.1e, |<a, y_k>|/h %.1e, |p . pdot| %.1e (|Omega| %.2f)\n", norm,
              aOm, ay, row0, Om);
  EXPECT_LT(norm, 4 * kEps);
  EXPECT_LT(aOm, 16 * kEps * Om);
  EXPECT_LT(ay, 64 * kEps * Om);
  EXPECT_LT(row0, 16 * kEps * Om);
}

// From a quaternion of norm s != 1 the motion is s times the unit one (suslov.hpp):
// the step keeps |p| = s and gives s times the unit run.
TEST(EpsCayley, KeepsANonUnitNormAndScales) {
  const FzScene f = scene_file("suslov.json");
  const double sc = 1.7;
  const auto a = run_eps(f.sys, f.q0, f.v0, 0.05, 200), b = run_eps(f.sys, sc * f.q0, sc * f.v0, 0.05, 200);
  double dq = 0, dn = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    dq = std::max(dq, (b[k].q - sc * a[k].q).cwiseAbs().maxCoeff());
    dn = std::max(dn, std::abs(b[k].q.norm() - sc));
  }
  EXPECT_LT(dq, 1e-12);
  EXPECT_LT(dn, 16 * kEps);
}

// Energy over a long horizon on suslov.json: |E - E0| is O(h^2) and does
// not come back after the turnover: the discrete flow settles on a steady
// rotation c_h e1 with c_h - c = O(h^2) (below), so E stays off by O(h^2),
// as at T/4, and is flat in the last quarter of T = 2000.
TEST(EpsCayley, EnergyErrorIsSecondOrderAndSettles) {
  const FzScene f = scene_file("suslov.json");
  const double E0 = energy(f.sys, f.q0, f.v0);
  for (double h : {0.2, 0.1, 0.05}) {
    const long steps = std::lround(2000 / h);
    double worst = 0, first_end = 0, last_lo = 1e300, last_hi = -1e300;
    const RunReport rep =
        integrate(EpsCayleyStepper<Suslov>(f.sys), f.q0, f.v0, h, steps, [&](const Sample<4, 2>& s) {
          const double dE = energy(f.sys, s.q, s.v) - E0;
          worst = std::max(worst, std::abs(dE));
          if (s.k == steps / 4) first_end = dE;
          if (s.k >= 3 * steps / 4) last_lo = std::min(last_lo, dE), last_hi = std::max(last_hi, dE);
          return true;
        });
    ASSERT_TRUE(rep.ok) << rep.reason;
    std::printf("    h = %-5g max |E - E0| = %.2e (%.1e E0 / h^2), E - E0 at T/4 %.2e, spread in the last quarter %.1e\n",
                h, worst, worst / (E0 * h * h), first_end, last_hi - last_lo);
    EXPECT_LT(worst, 0.3 * E0 * h * h);  // (measured 0.064)
    EXPECT_GT(std::abs(first_end), 0.5 * worst);
    EXPECT_LT(last_hi - last_lo, 1e-6 * worst);  // (measured at most 2.4e-7)
  }
}

// Self-adjoint and rho-reversible in (q, v), through the stepper's phase (q, p):
// h then -h returns to the start; from (q_1, -v_1) a step of h reaches (q_0, -v_0).
TEST(EpsCayley, ReturnsAfterHThenMinusHAndUnderTheVelocityFlip) {
  const FzScene f = scene_file("suslov.json");
  for (double h : {0.2, -0.1}) {
    EpsCayleyStepper<Suslov> st(f.sys);
    st.start(f.q0, f.v0);
    const Vec<double, 8> z0 = st.phase();
    ASSERT_TRUE(st.step(h).ok());
    Sample<4, 2> s1;
    st.sample(&s1);
    ASSERT_TRUE(st.step(-h).ok());
    const Vec<double, 8> z2 = st.phase();
    EpsCayleyStepper<Suslov> rev(f.sys);
    rev.start(s1.q, -s1.v);
    ASSERT_TRUE(rev.step(h).ok());
    Sample<4, 2> s2;
    rev.sample(&s2);
    const double scale = 1 + z0.cwiseAbs().maxCoeff();
    const double sym = (z2 - z0).cwiseAbs().maxCoeff() / scale;
    const double rq = (s2.q - f.q0).cwiseAbs().maxCoeff(), rv = (s2.v + f.v0).cwiseAbs().maxCoeff();
    std::printf("    h = %g: |Phi_-h Phi_h z0 - z0| = %.1e, rho-reversibility q %.1e, v %.1e\n", h, sym, rq, rv);
    EXPECT_LT(sym, 64 * kEps);
    EXPECT_LT(rq, 64 * kEps);
    EXPECT_LT(rv, 64 * kEps * (1 + f.v0.cwiseAbs().maxCoeff()));
  }
}

// The claim to measure: on suslov.json the continuous flow leaves -c e1 and
// tends to the steady rotation +c e1 with w = <Omega, b> ~ exp(-kappa t),
// kappa = k c / J (test_rigid.cpp: the sleigh's reduced equations).  The
// discrete flow of eps_cayley travels there too: Omega_k -> c_h e1 with
// c_h - c = O(h^2), and its w decays at a rate kappa_h (fitted to log|w| on
// 1e-10 < |w| < 1e-3 after the turnover) with kappa_h - kappa = O(h^2).
// dla_group (exp chart, the same discrete constraint set) and the embedded
// midpoint DLA (dla a=0.5, a different one) are measured beside it (printed).
struct Decay {
  double rate = NAN, u_end = NAN;
  bool ok = false;
};
Decay decay(const Suslov& sys, const MethodSpec& spec, const Vec4& q0, const Vec4& v0, double h, double T) {
  const Vec3 a = sys.suslov_axis().normalized(), b(0, a[2], -a[1]);
  std::vector<double> t, lw;
  Decay d;
  const RunReport rep = run_method(sys, spec, q0, v0, h, std::lround(T / h), [&](const Sample<4, 2>& s) {
    const Vec3 Om = body_rate(s.q, s.v);
    const double w = std::abs(Om.dot(b));
    if (s.t > 8.0 && w < 1e-3 && w > 1e-10) t.push_back(s.t), lw.push_back(std::log(w));
    d.u_end = Om[0];
    return true;
  });
  d.ok = rep.ok;
  if (t.size() < 5) return d;
  const double n = double(t.size());
  double st = 0, sl = 0, stt = 0, stl = 0;
  for (size_t i = 0; i < t.size(); ++i) st += t[i], sl += lw[i], stt += t[i] * t[i], stl += t[i] * lw[i];
  d.rate = -(n * stl - st * sl) / (n * stt - st * st);
  return d;
}

TEST(EpsCayley, FedorovZenkovDiscreteFlowTravelsToTheSteadyRotation) {
  const FzScene f = scene_file("suslov.json");
  const Suslov& sys = f.sys;
  const Vec3 a = sys.suslov_axis(), b(0, a[2], -a[1]), Jv = sys.inertia();
  const Vec3 Om0 = body_rate(f.q0, f.v0);
  const double E = 0.5 * Om0.dot(Jv.cwiseProduct(Om0)), c = std::sqrt(2 * E / sys.I1);
  const double Jb = b.dot(Jv.cwiseProduct(b)), k = -Vec3::UnitX().dot(b.cross(Jv.cwiseProduct(b)));
  const double kappa = k * c / Jb;
  std::printf("    continuous: c = %.7f, kappa = %.6f\n", c, kappa);
  const double T = 40;
  std::vector<double> hs, dk, dc;
  for (double h : {0.2, 0.1, 0.05, 0.025}) {
    const Decay d = decay(sys, spec_of("eps_cayley"), f.q0, f.v0, h, T);
    ASSERT_TRUE(d.ok);
    ASSERT_TRUE(std::isfinite(d.rate)) << "h = " << h << ": no decay window";
    hs.push_back(h), dk.push_back(std::abs(d.rate - kappa)), dc.push_back(std::abs(d.u_end - c));
    const Decay g = decay(sys, spec_of("dla_group"), f.q0, f.v0, h, T);
    const Decay m = decay(sys, spec_of("dla"), f.q0, f.v0, h, T);
    std::printf(
        "    h = %-6g eps-cayley kappa_h %.6f (kappa_h - kappa %+.2e), u_end - c %+.2e | dla-group %.6f (%+.2e), "
        "u_end - c %+.2e | dla a=0.5 %.6f (%+.2e), u_end - c %+.2e\n",
        h, d.rate, d.rate - kappa, d.u_end - c, g.rate, g.rate - kappa, g.u_end - c, m.rate, m.rate - kappa,
        m.u_end - c);
    EXPECT_GT(d.u_end, 0.0);  // it turned over
  }
  const OrderFit fk = fit_order(hs, dk, 1e-9), fc = fit_order(hs, dc, 1e-12);
  ASSERT_TRUE(fk.order);
  std::printf("    kappa_h - kappa: fitted order %.3f; u_end - c: %s\n", *fk.order,
              fc.order ? std::to_string(*fc.order).c_str() : "below 1e-12");
  EXPECT_NEAR(*fk.order, 2.0, 0.15);
  EXPECT_LT(dk.front(), 0.02 * kappa);  // h = 0.2: within 2 %
  ASSERT_TRUE(fc.order);
  EXPECT_NEAR(*fc.order, 2.0, 0.15);  // c_h - c = O(h^2)
}

}  // namespace
}  // namespace nhi::test
