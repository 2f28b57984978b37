// The bodies of DlaPredictor's members (dla_predictor.hpp): the construction,
// the passes and polish().  Included by dla_body.hpp, whose DlaStepper
// members are the predictor's only callers, so the library compiles them with
// the stepper's instances.
#pragma once

#include <algorithm>
#include <cmath>

#include "nhi/methods/dla/dla.hpp"
#include "nhi/methods/dla/dla_predictor.hpp"

namespace nhi {

template <class S, class D>
DlaPredictor<S, D>::DlaPredictor(const S& sys, const D& disc) {
  if constexpr (kSolvesMultipliers) {
    // M^-1 (constant on a separable system) and kappa = sum_c w_c c (1 - c)
    // for the curvature of the passes.
    Minv_ = inverse_mass_matrix(sys);
    passes_settle_ = constraint_force_misses_omega(sys);
    for (const Node& nd : disc.nodes()) kappa_ += nd.weight * nd.c * (1.0 - nd.c);
    // With kappa = 0 and passes that settle, the Gauss-Seidel pass
    // (constrained_pass) is exact in its first pass: one pass, then the check.
    gs_ = passes_settle_ && kappa_ == 0;
    if (kappa_ != 0) {
      // The curvature of the passes is used only where K is constant (a
      // quadratic potential) and not zero (K = 0: nothing to add).
      if (const auto K = constant_force_jacobian(sys)) {
        affine_potential_force_ = true;
        if ((K->array() != 0.0).any()) K_ = *K;
      } else {
        // A potential of one coordinate r (the robot's V0 sin psi): the
        // passes take its curvature at every pass (Newton passes).
        const std::array<bool, n> reads = force_reads(sys);
        int count = 0;
        for (int j = 0; j < n; ++j)
          if (reads[j]) {
            ++count;
            curvature_coordinate_ = j;
          }
        if (count != 1) curvature_coordinate_ = -1;
      }
    }
  }
}

// Rules with an interior node (kappa = sum_c w_c c (1 - c) > 0: alpha = 1/2,
// the paper's second-order rule) see q_guess in dL/dq too, and frozen there a
// pass gains only a factor ~ h^2 kappa |d^2 U| (the particle at h = 0.2:
// ~0.02), too little to settle in kMinPasses.  Where dL/dq is affine in q (a
// quadratic potential: K = d(dL/dq)/dq is constant, found at construction),
//     dL/dq(q_c) = dL/dq(q_c,guess) + c K (q_next - q_guess),  q_next - q_guess = h (v - v_guess)
// exactly, and the first line of eq. (6) is
//     (M - h^2 kappa K) v = rhs - h^2 kappa K v_guess - omega(q_{k+1})^T lambda:
// the passes use P = (M - h^2 kappa K)^-1 instead of V(qbar, .) = M^-1, and
// are then exact in the potential, so the particle's settle like the
// symmetric rule's.  At a fixed point the added terms cancel (v = v_guess):
// it is still the step's solution.  (With a non-quadratic potential the same
// passes with K taken once per step, one Jet evaluation, contract too little
// to settle in kMinPasses, and the Jet costs more than the passes save.)
// Only where a plain pass gains less than 10^6 (its factor is about rho =
// h^2 kappa |M^-1 K|): below, two plain passes reach round-off from the
// extrapolation and P would only cost.
template <class S, class D>
auto DlaPredictor<S, D>::make_curvature(double h) const -> Curvature {
  Curvature c;
  c.hkK = (h * h * kappa_) * *K_;
  const Mat<double, n, n> MhkK = Minv_ * c.hkK;
  const Mat<double, n, n> G = Mat<double, n, n>::Identity() - MhkK;  // M^-1 (M - h^2 kappa K)
  const double det = G.determinant();
  if (MhkK.cwiseAbs().maxCoeff() >= 1e-6 && std::isfinite(det) &&
      std::abs(det) > 0.5) {  // h^2 kappa K small against M
    c.P = G.inverse() * Minv_;
    c.ok = all_finite(c.P);
  }
  return c;
}

template <class S, class D>
void DlaPredictor<S, D>::refine(const S& sys, const D& disc, double h, const VecN& q, const VecN& p, int passes,
                                bool extend, Memo* memo, VecN* q_guess, VecM* lambda_guess, bool* settled) {
  last_.ok = false;
  Wt_ = DlaStepProblem<S, D>::force_forms(sys, q).transpose();
  double cbar = 0;
  for (const Node& nd : disc.nodes()) cbar += nd.weight * nd.c;
  // Without the multiplier solve the passes converge to a fixed point with
  // the extrapolated multipliers, not to the step: one pass gets all there is.
  if constexpr (!kSolvesMultipliers) passes = std::min(passes, 1);
  // The passes only make a starting iterate (Newton or the check judges the
  // result), so they multiply by 1/h: a division is the slowest link of
  // their dependency chain.
  const double inv_h = 1.0 / h;
  // P for the last two step sizes (the triple jump and Suzuki's composition
  // alternate between two).
  if constexpr (kSolvesMultipliers)
    if (K_) curv_.at(h, [this](double hh) { return make_curvature(hh); });
  const bool curved = K_ && curv_.current().ok;
  Mat<double, n, mc> PWt;
  if (curved) PWt = curv_.current().P * Wt_;
  if constexpr (kSolvesMultipliers) last_.curved = curved;
  const Step st{sys, disc, h, inv_h, cbar, q, p, curved, PWt};
  // Newton passes are a separate instantiation, so that the other passes
  // compile without them: a runtime branch in one shared loop makes the
  // particle's and the contact oscillator's steps slower.
  if (curvature_coordinate_ >= 0) {
    run_passes<true>(st, passes, extend, memo, q_guess, lambda_guess, settled);
  } else {
    run_passes<false>(st, passes, extend, memo, q_guess, lambda_guess, settled);
  }
}

template <class S, class D>
template <bool kNewton>
void DlaPredictor<S, D>::run_passes(const Step& st, int passes, bool extend, Memo* memo, VecN* q_guess,
                                    VecM* lambda_guess, bool* settled) {
  const VecN& q = st.q;
  Reuse reuse;
  PassIn in;
  in.r = kNewton ? curvature_coordinate_ : -1;
  for (int pass = 0; pass < passes; ++pass) {
    pass_sums<kNewton>(st, *q_guess, &in);
    VecM lambda = *lambda_guess;
    VecN q1;
    bool newton = false;
    if constexpr (kSolvesMultipliers) {
      newton = constrained_pass<kNewton>(st, in, &reuse, memo, q_guess, &q1, &lambda);
    } else {
      q1 = q + st.h * velocity<S, double>(st.sys, in.qbar, VecN(in.rhs - Wt_ * lambda));
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
    if constexpr (kNewton)  // (extend: refine())
      if (extend && newton && pass == passes - 1 && passes < kMaxNewtonPasses &&
          (q1 - q_before).cwiseAbs().maxCoeff() > kSqrtEps * (1.0 + q.cwiseAbs().maxCoeff()))
        ++passes;
  }
}

// A pass's right side rhs = p_{k+1} + h sum_c w_c (1 - c) dL/dq(q_c, v_guess)
// (eq. 6, first line, without the force) and, for Newton passes, the
// curvature of the potential of one coordinate r,
//     u = h^2 sum_c w_c c (1 - c) d(dL/dq)/dq_r  at the nodes,
// by a Jet of one derivative.
template <class S, class D>
template <bool kNewton>
void DlaPredictor<S, D>::pass_sums(const Step& st, const VecN& q_guess, PassIn* in) const {
  // (Locals, stored into *in at the end: the partials take their arguments
  // by reference, which would keep *in in memory across the node loop.)
  const VecN& q = st.q;
  const double h = st.h;
  const int r = in->r;
  const VecN vg = (q_guess - q) * st.inv_h;
  VecN rhs = st.p;
  VecN u;
  if constexpr (kNewton) u.setZero();
  for (const Node& nd : st.disc.nodes()) {
    VecN Lq, Lv;
    if constexpr (kNewton) {
      const VecN qc = (1.0 - nd.c) * q + nd.c * q_guess;
      const double wcc = nd.weight * nd.c * (1.0 - nd.c);
      if (wcc != 0) {
        VecN dLq;
        partials_and_curvature(st.sys, qc, vg, r, &Lq, &dLq);
        u += (h * h * wcc) * dLq;
      } else {
        lagrangian_partials(st.sys, qc, vg, &Lq, &Lv);
      }
    } else {
      lagrangian_partials(st.sys, VecN((1.0 - nd.c) * q + nd.c * q_guess), vg, &Lq, &Lv);
    }
    rhs += (h * nd.weight * (1.0 - nd.c)) * Lq;
  }
  in->vg = vg;
  in->rhs = rhs;
  if constexpr (kNewton) in->u = u;
  in->qbar = (1.0 - st.cbar) * q + st.cbar * q_guess;
}

// V(q, W^T e_a): V(q, .) does not depend on q on a separable system, so the
// same for every pass (Newton passes can hand over to the plain ones after
// pass 0, at large h).
template <class S, class D>
void DlaPredictor<S, D>::plain_forms(const Step& st, const VecN& qbar, Reuse* reuse) const {
  if (reuse->vwt_ready) return;
  for (int a = 0; a < m; ++a) reuse->VWt.col(a) = velocity<S, double>(st.sys, qbar, VecN(Wt_.col(a)));
  reuse->vwt_ready = true;
}

// One pass that solves for the multipliers too (kSolvesMultipliers), into
// *q1 and *lambda; true for a Newton pass.  Records the pass's matrices for
// polish().
template <class S, class D>
template <bool kNewton>
bool DlaPredictor<S, D>::constrained_pass(const Step& st, const PassIn& in, Reuse* reuse, Memo* memo, VecN* q_guess,
                                          VecN* q1, VecM* lambda) {
  const S& sys = st.sys;
  const VecN& q = st.q;
  const double h = st.h;
  Mat<double, m, m> Sinv;
  // Newton passes: z = M^-1 u, and whether h^2 curvature is small against M
  // (|1 - z_r| > 1/2, as for P; else the plain pass below).  z is kept for
  // polish(), which applies (M - u e_r^T)^-1 = (I + z e_r^T / (1 - z_r)) M^-1.
  VecN z;
  double zs = 0;
  if constexpr (kNewton) {
    z = Minv_ * in.u;
    if (std::abs(1.0 - z[in.r]) > 0.5) zs = 1.0 / (1.0 - z[in.r]);
  }
  VecN vfree;  // the plain pass's V(qbar, rhs)
  if (gs_) {   // (then kappa = 0: neither curvature applies, the pass is the plain one below)
    plain_forms(st, in.qbar, reuse);
    // Gauss-Seidel: in a coordinate whose row of V(q, W^T) is zero (one the
    // constraint force does not move) this pass's q1 is q + h V(qbar, rhs),
    // whatever the multipliers, so it goes into the guess before Omega is
    // taken at the constraint nodes.  Where the constraint rows read only
    // such coordinates the first pass is then exact in every coordinate, not
    // the second (first_pass_exact(): the symmetric rule alpha = 0 on the
    // paper's scenes and the contact and chaotic oscillators).  Kept to kappa
    // = 0: on every plain pass it makes the contact oscillator's midpoint DLA
    // slower.
    vfree = velocity<S, double>(sys, in.qbar, in.rhs);
    for (int i = 0; i < n; ++i)
      if ((reuse->VWt.row(i).array() == 0.0).all()) (*q_guess)[i] = q[i] + h * vfree[i];
  }
  Mat<double, m, n> Om = Mat<double, m, n>::Zero();
  int node = 0;
  for (const Node& nd : st.disc.constraint_nodes())  // (OmegaMemo: the robot's theta is exact after one pass)
    Om += nd.weight * memo->at(sys, node++, VecN((1.0 - nd.c) * q + nd.c * *q_guess));
  const bool newton = kNewton && zs != 0;
  if (newton) {
    newton_pass(st, in, Om, reuse, q1, lambda);
  } else if (st.curved) {  // through P (make_curvature)
    const VecN Prhs = curv_.current().P * VecN(in.rhs - curv_.current().hkK * in.vg);
    Sinv = Mat<double, m, m>(Om * st.PWt).inverse();
    *lambda = Sinv * VecM(Om * Prhs);
    *q1 = q + h * VecN(Prhs - st.PWt * *lambda);
  } else {
    plain_forms(st, in.qbar, reuse);
    if (!gs_) vfree = velocity<S, double>(sys, in.qbar, in.rhs);
    const Mat<double, m, m> A = Om * reuse->VWt;
    Sinv = A.inverse();
    *lambda = Sinv * VecM(Om * vfree);
    *q1 = q + h * velocity<S, double>(sys, in.qbar, VecN(in.rhs - Wt_ * *lambda));
  }
  last_.Om = Om;
  // (A Newton pass leaves (Omega G W^T)^-1 to polish(), which is rare.)
  last_.lazy = newton;
  if (!newton) last_.Sinv = Sinv;
  if constexpr (kNewton) {
    last_.zr = -1;
    if (zs != 0) {
      last_.z = zs * z;
      last_.zr = in.r;
    }
  }
  last_.ok = true;
  return newton;
}

// A potential of one coordinate r (dL/dq reads q_r alone, found by autodiff
// at construction: the robot's V0 sin psi).  K = d(dL/dq)/dq then has one
// column, and the first line of eq. (6), linearized in q_next at the guess, is
//     (M - u e_r^T) v = rhs - u vg_r - W^T lambda,  Omega v = 0
// (u: pass_sums): a Newton step in the potential, so the passes converge
// quadratically, the third is at round-off and the residual check confirms
// it (kNewtonPasses).  It is solved through the constrained inverse Pi of M,
// taken again only when Omega changes (the robot's from pass 1 on, theta
// being exact), so that nothing but Pi times two vectors and one division
// follows the curvature on the pass's chain: with x = rhs' + v_r u, rhs' =
// rhs - vg_r u, the system is M v = x - W^T lambda, Omega v = 0, so v = Pi x
// and lambda = S0 Omega M^-1 x, S0 = (Omega M^-1 W^T)^-1,
// Pi = M^-1 - M^-1 W^T S0 Omega M^-1; its row r gives
// v_r = (Pi rhs')_r / (1 - (Pi u)_r).  (The curvature of every coordinate, a
// Jet of n derivatives and an n x n inverse per pass, would remove the
// iterations too, but costs more per step than they do.)
template <class S, class D>
void DlaPredictor<S, D>::newton_pass(const Step& st, const PassIn& in, const Mat<double, m, n>& Om, Reuse* reuse,
                                     VecN* q1, VecM* lambda) const {
  if (!reuse->rank_one_started) {  // (W^T is the step's: once)
    reuse->MWt = Minv_ * Wt_;
    reuse->rank_one_started = true;
  }
  if (!reuse->pi_ready || !(Om.array() == reuse->pi_Om.array()).all()) {
    reuse->pi_Om = Om;
    reuse->pi_S0 = Mat<double, m, m>(Om * reuse->MWt).inverse();
    reuse->pi = Minv_ - reuse->MWt * Mat<double, m, n>(reuse->pi_S0 * Mat<double, m, n>(Om * Minv_));
    reuse->pi_ready = true;
  }
  const int r = in.r;
  const VecN rhs1 = in.rhs - in.vg[r] * in.u;
  const VecN Pu = reuse->pi * in.u, Prhs = reuse->pi * rhs1;
  const double vr = Prhs[r] / (1.0 - Pu[r]);
  *lambda = reuse->pi_S0 * VecM(Om * VecN(Minv_ * VecN(rhs1 + vr * in.u)));
  *q1 = st.q + st.h * VecN(Prhs + vr * Pu);
}

// The correction of a guess the residual check accepted by its second test
// (NewtonSolver::solve: at small h; where the first test, against the terms
// alone, accepts, the guess is a correctly rounded step without it), from
// its residual r = (r_f, r_g): one chord Newton step with the step matrix (7)
// taken as [-G^-1/h  -W^T; Omega/h  0], G = M^-1 (or P, or the Newton pass's
// inverse) and Omega the last pass's constraint form:
//     dlambda = (Omega G W^T)^-1 (Omega G r_f + r_g),
//     q1 += h G (r_f - W^T dlambda),  lambda += dlambda.
// The check accepts a point up to 16 eps of its scale from the zero of the
// residual, and at small h that scale holds |q|/h (solver.hpp), so a guess
// that is the passes' fixed point, or a pass short of it, could be a few eps
// |q| off, smoothly from step to step, and such offsets add up to a drift of
// the mean energy error over long runs (the contact oscillator's midpoint
// rule at small h) that Newton alone does not have (tests/test_dla.cpp).
// The correction's fixed point is the zero of the residual, and from a point
// already at round-off it moves by round-off, so it is taken without another
// residual.
template <class S, class D>
void DlaPredictor<S, D>::polish(double h, const Vec<double, n + mc>& r, VecN* q1, VecM* lambda) {
  if constexpr (kSolvesMultipliers) {  // (then there is no holonomic multiplier: mc = m)
    if (!last_.ok) return;
    // G x: P x, M^-1 x, or (I + z e_r^T / (1 - z_r)) M^-1 x.
    const auto G = [this](const VecN& x) -> VecN {
      if (last_.curved) return curv_.current().P * x;
      const VecN y = Minv_ * x;
      if (last_.zr < 0) return y;
      return y + y[last_.zr] * last_.z;
    };
    if (last_.lazy) {  // (Omega G W^T)^-1 of the last pass, a Newton pass
      const Mat<double, n, mc> MWt = Minv_ * Wt_;
      const Mat<double, n, mc> GWt = MWt + last_.z * MWt.row(last_.zr);
      last_.Sinv = Mat<double, mc, mc>(last_.Om * GWt).inverse();
      last_.lazy = false;
    }
    const VecN Grf = G(VecN(r.template head<n>()));
    const VecM dl = last_.Sinv * VecM(last_.Om * Grf + r.template tail<mc>());
    const VecN q = *q1 + h * G(VecN(r.template head<n>() - Wt_ * dl));
    const VecM l = *lambda + dl;
    if (all_finite(q) && all_finite(l)) {
      *q1 = q;
      *lambda = l;
    }
  }
}

}  // namespace nhi
