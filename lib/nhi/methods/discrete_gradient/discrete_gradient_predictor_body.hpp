// The bodies of DiscreteGradientPredictor's members
// (discrete_gradient_predictor.hpp): the construction and the passes.
// Included by discrete_gradient_body.hpp, whose DiscreteGradientStepper
// members are the predictor's only callers, so the library compiles them
// with the stepper's instances.
#pragma once

#include <algorithm>
#include <cmath>

#include "nhi/methods/discrete_gradient/discrete_gradient.hpp"
#include "nhi/methods/discrete_gradient/discrete_gradient_predictor.hpp"

namespace nhi {

template <class S>
DiscreteGradientPredictor<S>::DiscreteGradientPredictor(const S& sys) {
  if constexpr (is_separable<S>::value) {
    // The passes are exact in the force where K = dF/dq is constant (F
    // affine in q: a quadratic potential), with Q where K is not zero.
    if (const auto K = constant_force_jacobian(sys)) {
      affine_force_ = true;
      if ((K->array() != 0.0).any()) {
        K_ = *K;
        Minv_ = inverse_mass_matrix(sys);
        // The Gauss-Seidel first pass (curved_pass).
        gs_ = constraint_force_misses_omega(sys);
        omega_reads_ = omega_reads(sys);
      }
    }
  }
}

// Q and M^-1 Q for step size h, kept for the last two step sizes (the triple
// jump and Suzuki's composition alternate between two); K_ set.
template <class S>
auto DiscreteGradientPredictor<S>::curvature(double h) -> const Curvature& {
  curv_.at(h, [this](double hh) { return make_curvature(hh); });
  return curv_.current();
}

// Only where a plain pass gains less than ~2000 (its factor is about rho =
// (h^2/4) |K M^-1|): below, the plain passes settle in about as many passes
// as the curved ones and the hand-over.
//   The first pass is a Gauss-Seidel pass exact from any input
// (first_pass_exact): gs_ says that M^-1 W^T misses the coordinates omega
// reads; M^-1 Q W^T does too where each such coordinate j has one entry in
// its row of M^-1, at column k, and its row of M^-1 Q none but there (then
// gs_ makes W's column k zero, and with it (M^-1 Q W^T)_j).  A sufficient
// test, not a necessary one: a system it misses starts its passes from the
// explicit guess.
template <class S>
auto DiscreteGradientPredictor<S>::make_curvature(double h) const -> Curvature {
  Curvature cv;
  const Mat<double, n, n> hKM = (0.25 * h * h) * (*K_ * Minv_);
  const Mat<double, n, n> G = Mat<double, n, n>::Identity() - hKM;
  const double det = G.determinant();
  if (hKM.cwiseAbs().maxCoeff() >= 5e-4 && std::isfinite(det) && std::abs(det) > 0.5) {  // (h^2/4) K small against M
    cv.Q = G.inverse();
    cv.MQ = Minv_ * cv.Q;
    cv.ok = all_finite(cv.Q);
    if (cv.ok && gs_) {
      cv.first_pass_exact = true;
      for (int j = 0; j < n; ++j) {
        if (!omega_reads_[j]) continue;
        int k = -1, entries = 0;
        for (int c = 0; c < n; ++c)
          if (Minv_(j, c) != 0.0) ++entries, k = c;
        bool only_k = entries == 1;
        for (int c = 0; c < n && only_k; ++c)
          if (c != k && cv.MQ(j, c) != 0.0) only_k = false;
        cv.first_pass_exact = cv.first_pass_exact && only_k;
      }
    }
  }
  return cv;
}

// With a quadratic H and the passes exact in the force, a Gauss-Seidel first
// pass is exact whatever its input (the particle at h >= 0.032 with its
// default kx = ky = 1: h^2/2 >= 5e-4).
template <class S>
bool DiscreteGradientPredictor<S>::first_pass_exact(double h) {
  return gs_ && curvature(h).first_pass_exact;
}

// The passes settle (true: the solve starts with the residual check,
// NewtonSolver::solve) when a pass moves no component by more than 4 eps of
// the terms it is made of, or stops contracting (by 1/2) within 1e-10 of the
// state's size: at round-off the iterates wander in a cloud (lambda is set
// only to eps |H| / |dz|^2 through Gonzalez's c, and moves p by h omega^T
// lambda; measured 5e-14 at h = 0.4 / 2^9 on the particle), which the check
// judges.  Passes whose measured contraction predicts that they will not
// settle within kPasses are mixed (next_input), which spares the slow cases
// (large h, the sleigh) most of their passes and Newton iterations; at h <=
// 0.2 the passes are almost never mixed.  False when a pass contracts by less
// than 1/2 above that (diverging: Newton takes over from the explicit start),
// when the mixed passes still predict more than kPasses in all
// (mix_or_give_up), or after kPasses.
template <class S>
bool DiscreteGradientPredictor<S>::passes(const Problem& prob, VecY* y) {
  settled_by_move_ = false;
  return run(prob, y, true);
}

template <class S>
bool DiscreteGradientPredictor<S>::run(const Problem& prob, VecY* y, bool allow_curved) {
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  VecN q1 = y->template head<n>(), p1 = y->template segment<n>(n);
  const double size = 1 + q0.cwiseAbs().maxCoeff() + p0.cwiseAbs().maxCoeff();
  double last_move = std::numeric_limits<double>::infinity();
  Mixing mix;
  if (K_) curvature(prob.h);
  const bool curved = allow_curved && K_ && curv_.current().ok;
  for (int k = 0; k < kPasses; ++k) {
    PassOut out;
    if (!pass(prob, q1, p1, curved, k, &out)) return false;
    // No longer contracting: at round-off (the residual check judges) or diverging.
    if (!out.fixed && k > 0 && !(out.move <= 0.5 * last_move)) {
      if (!(last_move <= kStall * size)) return false;
      return curved ? run(prob, y, false) : true;  // (the plain passes end it: see below)
    }
    if (mix_or_give_up(out, q1, p1, k, last_move, size, &mix.from)) return false;
    last_move = out.move;
    *y << out.q1, out.p1, out.l;
    // Settled curved passes hand over to the plain ones, which then settle
    // at once (one pass, two at most): the curved passes' fixed point is the
    // step's solution, but their rounding is not that of the residual, and
    // ending on them would leave the energy drifting by ~0.5 ulp of H per
    // step (the particle at h = 0.2).
    // So does an exact Gauss-Seidel first pass, unconfirmed.
    if (out.fixed || out.exact) {
      if (!curved) settled_by_move_ = true;  // (a plain pass's fixed: DiscreteGradientStepper::map)
      return curved ? run(prob, y, false) : true;
    }
    next_input(out, k, &mix, &q1, &p1);
  }
  return false;
}

// One pass from (q1, p1) into *out; false when it is not finite.
template <class S>
bool DiscreteGradientPredictor<S>::pass(const Problem& prob, const VecN& q1, const VecN& p1, bool curved, int pass,
                                        PassOut* out) {
  const double h = prob.h;
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  // Dq = -F(qbar) + c dq and the frozen c dp, with the sizes sq, sp of
  // the residual's rows (DiscreteGradientProblem::discrete_gradient).
  VecN Dq, Dp, sq, sp;
  double c = 0;
  prob.template discrete_gradient<double>(q1, p1, &Dq, &Dp, &sq, &sp, &c);
  ++passes_made_;
  const VecN qb = 0.5 * (q0 + q1), cp = c * (p1 - p0);
  Mat<double, m, n> W = prob.sys.template omega<double>(qb);
  out->exact = false;
  out->l = VecM::Zero();
  if (curved) {
    curved_pass(prob, q1, Dq, cp, qb, pass, &W, out);
  } else {
    plain_pass(prob, Dq, cp, qb, W, out);
  }
  if (!(all_finite(out->q1) && all_finite(out->p1) && all_finite(out->l))) return false;
  out->move = std::max((out->q1 - q1).cwiseAbs().maxCoeff(), (out->p1 - p1).cwiseAbs().maxCoeff());
  // Settled: no component moved by more than 4 eps of the terms that make
  // it (those of the residual's rows, DiscreteGradientProblem::residual).
  const VecN fs = W.cwiseAbs().transpose() * out->l.cwiseAbs();
  out->bound_q = kSettled * (q0.cwiseAbs() + out->q1.cwiseAbs() + std::abs(h) * sp);
  out->bound_p = kSettled * (p0.cwiseAbs() + out->p1.cwiseAbs() + std::abs(h) * (sq + fs));
  out->fixed = ((out->q1 - q1).cwiseAbs() - out->bound_q).maxCoeff() <= 0 &&
               ((out->p1 - p1).cwiseAbs() - out->bound_p).maxCoeff() <= 0;
  return true;
}

// A pass exact in the force (F affine in q: a quadratic potential, K = dF/dq
// constant: the particle).  F(qbar) is not frozen but exact,
//     F(qbar') = F(qbar) + K (qbar' - qbar),  qbar' = (q0 + q1')/2
//              = d0 + qbar + (h/4) M^-1 p1',  d0 = q0 + (h/2) c dp + (h/4) M^-1 p0 - qbar,
// so p1' = Q b + h Q W^T lambda, b = p0 - h Dq + h K d0, Q = (I - (h^2/4) K M^-1)^-1,
// and the constraint W (M^-1 (p0 + p1')/2 + c dp) = 0 gives lambda.  On the
// particle the constraint row then reads a y that is exact after one pass,
// and the passes settle in three at h = 0.2.
//   Gauss-Seidel first pass: where, besides, the constraint force misses the
// coordinates omega reads (constraint_force_misses_omega; rows of
// M^-1 Q W^T zero there, checked on the pass's own matrix), those
// coordinates of q1' do not depend on lambda, so the first pass takes them,
// q1'_j = q0_j + h (M^-1 (p0 + Q b)/2 + c dp)_j, before it evaluates
// W = omega(qbar) (into *W).  With H quadratic Gonzalez's c is zero up to its
// rounding whatever the iterate, so that pass is exact, not the second: it
// hands over to the plain passes at once, two passes a step on the particle
// instead of four (three curved, one plain).
template <class S>
void DiscreteGradientPredictor<S>::curved_pass(const Problem& prob, const VecN& q1, const VecN& Dq, const VecN& cp,
                                               const VecN& qb, int pass, Mat<double, m, n>* W, PassOut* out) const {
  const double h = prob.h;
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  const Mat<double, n, n>& Q = curv_.current().Q;
  const Mat<double, n, n>& MQ = curv_.current().MQ;
  const VecN d0 = q0 + (0.5 * h) * cp + (0.25 * h) * (Minv_ * p0) - qb;
  const VecN b = p0 - h * Dq + h * (*K_ * d0);
  const VecN Qb = Q * b;
  if constexpr (m > 0) {
    // V((p0 + p1')/2) + c dp without the constraint force's part.
    const VecN vfree = VecN(0.5 * (Minv_ * VecN(p0 + Qb))) + cp;
    Mat<double, n, m> MQWt = MQ * W->transpose();
    if (pass == 0 && gs_ && misses_omega(MQWt)) {
      VecN qg = q1;
      for (int j = 0; j < n; ++j)
        if (omega_reads_[j]) qg[j] = q0[j] + h * vfree[j];
      *W = prob.sys.template omega<double>(VecN(0.5 * (q0 + qg)));
      MQWt = MQ * W->transpose();
      out->exact = misses_omega(MQWt);
    }
    const Mat<double, m, m> A = (0.5 * h) * (*W * MQWt);
    out->l = -(A.inverse() * (*W * vfree));
    out->p1 = Qb + h * (Q * (W->transpose() * out->l));
  } else {
    out->p1 = Qb;
  }
  out->q1 = q0 + h * (VecN(0.5 * (Minv_ * VecN(p0 + out->p1))) + cp);
}

// The plain pass (the equations at the top of discrete_gradient_predictor.hpp).
template <class S>
void DiscreteGradientPredictor<S>::plain_pass(const Problem& prob, const VecN& Dq, const VecN& cp, const VecN& qb,
                                              const Mat<double, m, n>& W, PassOut* out) const {
  const S& sys = prob.sys;
  const double h = prob.h;
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  if constexpr (m > 0) {
    Mat<double, m, m> A;
    for (int a = 0; a < m; ++a)
      A.col(a) = W * velocity<S, double>(sys, qb, VecN((0.5 * h) * W.row(a).transpose()));
    out->l = -(A.inverse() * (W * VecN(velocity<S, double>(sys, qb, VecN(p0 - (0.5 * h) * Dq)) + cp)));
  }
  out->p1 = p0 - h * (Dq - W.transpose() * out->l);
  out->q1 = q0 + h * (velocity<S, double>(sys, qb, VecN(0.5 * (p0 + out->p1))) + cp);
}

// Does the constraint force M^-1 Q W^T lambda miss every coordinate omega reads?
template <class S>
bool DiscreteGradientPredictor<S>::misses_omega(const Mat<double, n, m>& moved) const {
  for (int j = 0; j < n; ++j)
    if (omega_reads_[j] && !(moved.row(j).array() == 0.0).all()) return false;
  return true;
}

// Passes still needed at the contraction r = move / last_move just measured:
// log(1 / excess) / log r.  More than are left (kPasses - pass - 1) iff
// excess r^left > 1, tested without logarithms (two per pass would be a
// noticeable share of a step).  Then the passes are mixed from here on
// (*mix_from = pass; next_input).  The excess, not the move against the
// state's size: the sleigh's passes crawl in a component much smaller than
// the state, and against the state they look as if they would make it, run
// out, and leave Newton several iterations.  If, two passes into the mixing,
// even the move against the state's size (4 eps size / move < r^left, the
// lenient test: a give-up costs a Newton solve, and at h = 0.4 mixed passes
// that fail the strict test often settle) predicts more than kPasses, they
// give up (true; at h = 0.4 unmixed passes contract by only ~0.1-0.4, and
// without the give-up all of them would run before Newton does).  The test
// runs on the first kPredict passes and two passes into the mixing only: on
// every pass its divisions and powers would be a noticeable share of a step
// at h = 0.1-0.2, where it almost never fires.
template <class S>
bool DiscreteGradientPredictor<S>::mix_or_give_up(const PassOut& out, const VecN& q1, const VecN& p1, int pass,
                                                  double last_move, double size, int* mix_from) const {
  if (out.fixed || !(pass > 0) || !(*mix_from < 0 ? pass <= kPredict : pass == *mix_from + 2)) return false;
  const double r = out.move / last_move;
  double r_left = 1;
  for (int j = pass + 1; j < kPasses; ++j) r_left *= r;
  if (*mix_from < 0) {
    // The excess: the largest move over its own bound (settled: <= 1).
    constexpr double tiny = std::numeric_limits<double>::min();  // a zero bound: 0 / tiny = 0
    const double excess = std::max((out.q1 - q1).cwiseAbs().cwiseQuotient(out.bound_q.cwiseMax(tiny)).maxCoeff(),
                                   (out.p1 - p1).cwiseAbs().cwiseQuotient(out.bound_p.cwiseMax(tiny)).maxCoeff());
    if (excess * r_left > 1) *mix_from = pass;
    return false;
  }
  return out.move * r_left > kSettled * size;
}

// The next input: the output g, or once the passes are found too slow, g
// mixed with the last output,
//     x' = g - gamma (g - g_prev),  gamma = <df, f> / <df, df>,  df = f - f_prev,
// the secant step along the last two moves f = g - x (Anderson mixing of
// depth 1; Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715, type II with
// m = 1).  It removes the slowest direction of the passes' linear
// contraction, the one the sleigh's passes crawl along.  A |gamma| above
// kMaxGamma (nearly parallel moves, at round-off) keeps g.  Only slow passes
// are mixed: the mixing puts dot products and a division on the passes'
// dependency chain, which makes fast passes slower even where it saves one
// or two of them.
template <class S>
void DiscreteGradientPredictor<S>::next_input(const PassOut& out, int pass, Mixing* mix, VecN* q1, VecN* p1) const {
  if (mix->from < 0) {
    *q1 = out.q1;
    *p1 = out.p1;
    return;
  }
  Vec<double, 2 * n> g, f;
  g << out.q1, out.p1;
  f << out.q1 - *q1, out.p1 - *p1;
  Vec<double, 2 * n> x = g;
  if (pass > mix->from) {
    const Vec<double, 2 * n> df = f - mix->f_prev;
    const double dd = df.squaredNorm();
    if (dd > 0) {
      const double gamma = df.dot(f) / dd;
      if (std::abs(gamma) <= kMaxGamma) x = g - gamma * (g - mix->g_prev);
    }
  }
  mix->f_prev = f;
  mix->g_prev = g;
  *q1 = x.template head<n>();
  *p1 = x.template tail<n>();
}

}  // namespace nhi
