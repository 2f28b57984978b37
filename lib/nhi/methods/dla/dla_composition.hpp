// The paper's DLA composed: the variable-step DLA
//     D2 L_d^{h_{k-1}}(q_{k-1}, q_k) + D1 L_d^{h_k}(q_k, q_{k+1}) = omega(q_k)^T lambda_k   (eq. 6)
// with h_k cycling through the stage steps gamma_i h of a composition
// (composition.hpp).  The DLA is not self-adjoint on T*Q (the constraint force
// acts at q_k only, dla.hpp), but a step sees p_k only modulo the span of
// omega(q_k)^T, which lambda_k absorbs, and p_{k+1} depends on positions alone;
// so the DLA is a one-step map on (q, p mod omega(q)^T), and with a self-adjoint
// discretization (alpha = 1/2, the symmetric family) that map is self-adjoint:
// a step of h then -h returns q and p mod omega^T.  Composition then raises its
// order like any symmetric method's: measured 4 for the triple jump on both
// paper scenes (tests/test_dla_composition.cpp, README "Methods").
//
// Reported per full step h: q_k, p_k = D2 L_d of the last stage, and the velocity
// of the class of p_k that lies in the constraint distribution,
//     v_k = V(q_k, p_k + omega(q_k)^T mu),  omega(q_k) v_k = 0,
// which depends only on p_k mod omega^T (so it is of the composition's order;
// the plain DLA's central difference would be of order 2 across stages of
// different lengths).  v_0 is the given v0.
#pragma once

#include <Eigen/LU>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "nhi/methods/composition.hpp"
#include "nhi/methods/dla/dla.hpp"
#include "nhi/methods/method_spec.hpp"
#include "nhi/methods/spec_options.hpp"
#include "nhi/roles/hamiltonian.hpp"

namespace nhi {

template <class S, class D>
class ComposedDla {
 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;

  ComposedDla(const S& sys, const D& disc, DlaOptions options, const Composition& c)
      : dla_(sys, disc, options), c_(c) {}

  const S& system() const { return dla_.system(); }

  MethodTraits traits() const {
    MethodTraits t = dla_.traits();
    if (t.symmetric) t.order = c_.order;  // a non-symmetric DLA gains nothing from composition
    t.stages = static_cast<int>(c_.gamma.size());
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    dla_.start(q0, v0);
    v0_ = v0;
    steps_ = 0;
  }

  StepSummary step(double h) {
    StepSummary total;
    for (size_t i = 0; i < c_.gamma.size(); ++i) {
      if (!add_stage(c_, i, dla_.step(c_.gamma[i] * h), &total)) return total;
    }
    ++steps_;
    total.status = SolveStatus::kConverged;
    return total;
  }

  // Point k: q_k, v_k (see the top of this file), p_k, the multiplier and the
  // discrete constraint omega_d of the last stage (the one that arrived at q_k).
  void sample(Sample<n, m>* s) const {
    if (steps_ == 0) {
      const Vec<double, 2 * n> z = dla_.phase();
      s->has_p = true;
      s->q = z.template head<n>();
      s->v = v0_;
      s->p = z.template tail<n>();
      s->lambda.setZero();
      s->discrete_constraint.setZero();
      return;
    }
    dla_.sample(s);  // lambda and omega_d of the last stage; q, v, p are replaced below
    const Vec<double, 2 * n> z = dla_.phase();
    s->q = z.template head<n>();
    s->p = z.template tail<n>();
    s->v = constrained_velocity(s->q, s->p);
  }

  Vec<double, 2 * n> phase() const { return dla_.phase(); }
  const auto& lambda() const { return dla_.lambda(); }

  // V(q, p + omega^T mu) with mu such that it satisfies the constraint; V is
  // affine in p (L quadratic in v), so V(q, p + omega^T mu) = V(q, p) + B mu with
  // B e_j = V(q, p + omega^T e_j) - V(q, p).
  VecN constrained_velocity(const VecN& q, const VecN& p) const {
    const S& sys = dla_.system();
    const Mat<double, m, n> W = sys.template omega<double>(q);
    const VecN v = velocity<S, double>(sys, q, p);
    Mat<double, n, m> B;
    for (int j = 0; j < m; ++j) B.col(j) = velocity<S, double>(sys, q, VecN(p + W.row(j).transpose())) - v;
    const Vec<double, m> mu = (W * B).partialPivLu().solve(Vec<double, m>(-W * v));
    return v + B * mu;
  }

 private:
  DlaStepper<S, D> dla_;
  Composition c_;
  VecN v0_ = VecN::Zero();
  long steps_ = 0;
};

// The method table's entry (methods.hpp): "dla", the paper's method.
struct DlaMethod {
  static constexpr const char* name = "dla";
  static constexpr bool adaptive = false;
  // The paper's discretizations: L_d^alpha, omega_d^alpha (eqs. 9, 13) or the
  // symmetric L_d^{sym,alpha}, omega_d^{sym,alpha} (eqs. 10, 14); alpha in [0, 1].
  static std::vector<MethodKey> keys() {
    return {MethodKey::choice("discretization", &MethodSpec::discretization, {"alpha", "symmetric"}),
            MethodKey::range("alpha", &MethodSpec::alpha, 0.0, 1.0)};
  }
  static constexpr bool reports_p = true;
  static constexpr double step_cost = 6.0;
  static std::string label(const MethodSpec& spec) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s a=%g", spec.discretization == "alpha" ? "dla" : "dla-sym", spec.alpha);
    return buf;
  }
  // Self-adjoint discretizations (alpha = 1/2, the symmetric family) compose:
  // dla_composition.hpp, README "Methods".
  // The discretizations' own symmetric() (discretization.hpp) says which.
  static bool symmetric(const MethodSpec& spec) {
    return spec.discretization == SymmetricDiscretization::kind ? SymmetricDiscretization{spec.alpha}.symmetric()
                                                                : AlphaDiscretization{spec.alpha}.symmetric();
  }
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    const DlaOptions opt = solver_options(spec);
    if (spec.composition != "none") {
      if (!symmetric(spec)) throw std::invalid_argument("the DLA composes only with a self-adjoint discretization");
      const Composition& c = composition(spec.composition);
      if (spec.discretization == "alpha") {
        ComposedDla<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, opt, c);
        return f(st);
      }
      ComposedDla<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, opt, c);
      return f(st);
    }
    if (spec.discretization == "alpha") {
      DlaStepper<S, AlphaDiscretization> st(sys, AlphaDiscretization{spec.alpha}, opt);
      return f(st);
    }
    if (spec.discretization != "symmetric")
      throw std::invalid_argument("unknown discretization \"" + spec.discretization + "\"");
    DlaStepper<S, SymmetricDiscretization> st(sys, SymmetricDiscretization{spec.alpha}, opt);
    return f(st);
  }
  static std::vector<StudyEntry> study_entries() {
    auto dla = [](const char* disc, double alpha, const char* group, int style) {
      MethodSpec s;
      s.discretization = disc;
      s.alpha = alpha;
      return StudyEntry{s, group, style};
    };
    StudyEntry tj = dla("alpha", 0.5, "main", 12), tj_sym = dla("symmetric", 0.0, "variant", 14);
    tj.spec.composition = tj_sym.spec.composition = "triple_jump";
    return {dla("alpha", 0.5, "main", 11),
            dla("symmetric", 0.0, "main", 13),
            dla("alpha", 0.0, "variant", 15),
            dla("alpha", 0.25, "variant", 16),
            dla("alpha", 0.75, "variant", 17),
            dla("alpha", 1.0, "variant", 18),
            dla("symmetric", 0.25, "variant", 19),
            tj,
            tj_sym};
  }
};

}  // namespace nhi
