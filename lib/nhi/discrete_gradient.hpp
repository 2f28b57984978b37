// An energy-preserving nonholonomic scheme from Gonzalez's midpoint discrete
// gradient (O. Gonzalez, "Time integration and discrete Hamiltonian systems",
// J. Nonlinear Sci. 6, 1996, eq. 3.6; the nonholonomic form with the
// codistribution at the midpoint is also odelab's NonHolonomicEnergy).  With
// z = (q, p), zbar = (z0 + z1)/2, dz = z1 - z0 and H from hamiltonian.hpp:
//     gradbar H(z0, z1) = grad H(zbar) + [H(z1) - H(z0) - grad H(zbar) . dz] / |dz|^2  dz
// so that H(z1) - H(z0) = gradbar H . dz exactly; grad H = (-F(q, p), V(q, p)).
// One step solves, for (q1, p1, lambda), with qbar = (q0 + q1)/2:
//     (q1 - q0)/h =  gradbar_p H
//     (p1 - p0)/h = -gradbar_q H + omega(qbar)^T lambda
//     omega(qbar) gradbar_p H = 0
// Then H(z1) - H(z0) = h lambda . omega(qbar) gradbar_p H = 0: the energy is
// preserved to round-off for every h; the velocity constraint holds only in
// the averaged form of the third line.  Symmetric (exchanging z0, z1 and h -> -h
// leaves the equations unchanged) and of order 2.
//
// The constraint rows omega(qbar) move with q1, so lambda is one more unknown of
// a plain Newton solve (NewtonSolver with nl = 0, LU of the whole Jacobian).
// On a separable system fixed-point passes come first (passes() below), and
// a settled iterate is accepted by a residual check with no derivatives.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "nhi/composition.hpp"
#include "nhi/hamiltonian.hpp"
#include "nhi/method_spec.hpp"
#include "nhi/solver.hpp"

namespace nhi {

template <class S>
struct DiscreteGradientProblem {
  static constexpr int n = S::n, m = S::m;
  static constexpr int ny = 2 * n + m, nl = 0;
  using VecN = Vec<double, n>;

  const S& sys;
  double h;
  VecN q0, p0;
  double H0;
  Mat<double, ny, nl> W_t;  // empty: lambda is part of y

  DiscreteGradientProblem(const S& s, double hh, const VecN& q, const VecN& p)
      : sys(s), h(hh), q0(q), p0(p), H0(hamiltonian<S, double>(s, q, p)) {}

  const Mat<double, ny, nl>& Wt() const { return W_t; }

  Vec<double, ny> y_scale(const Vec<double, ny>& y) const {
    Vec<double, ny> s;
    s << q0.cwiseAbs() + y.template head<n>().cwiseAbs(), p0.cwiseAbs() + y.template segment<n>(n).cwiseAbs(),
        y.template tail<m>().cwiseAbs();
    return s;
  }

  // gradbar H(z0, z1) as (gradbar_q, gradbar_p).  With sq, sp (may be null):
  // per component the size of what it adds up, |grad H(zbar)| + |c dz| with c
  // taken at the size of its numerator's terms, |H1| + |H0| + |grad H . dz|
  // (over |dz|^2): the correction's rounding, which sets the floor of every
  // row that contains it (when the velocities in a constraint row vanish
  // together, it is all that is left of that row's size).  *c_out (may be
  // null) gets Gonzalez's coefficient c (0 when dz = 0).
  template <class T>
  void discrete_gradient(const Vec<T, n>& q1, const Vec<T, n>& p1, Vec<T, n>* Dq, Vec<T, n>* Dp,
                         VecN* sq = nullptr, VecN* sp = nullptr, T* c_out = nullptr) const {
    const Vec<T, n> qb = cst<T>(0.5) * (q0.template cast<T>() + q1), pb = cst<T>(0.5) * (p0.template cast<T>() + p1);
    const Vec<T, n> gq = -force(sys, qb, pb), gp = velocity(sys, qb, pb);
    const Vec<T, n> dq = q1 - q0.template cast<T>(), dp = p1 - p0.template cast<T>();
    const T den = dq.squaredNorm() + dp.squaredNorm();
    *Dq = gq;
    *Dp = gp;
    if (c_out) *c_out = cst<T>(0.0);
    double cs = 0;
    if (value_of(den) > 0) {  // Gonzalez's correction along dz (eq. 3.6)
      const T H1 = hamiltonian(sys, q1, p1);
      const T c = (H1 - cst<T>(H0) - gq.dot(dq) - gp.dot(dp)) / den;
      *Dq += c * dq;
      *Dp += c * dp;
      if (c_out) *c_out = c;
      double num = std::abs(value_of(H1)) + std::abs(H0);
      for (int i = 0; i < n; ++i)
        num += std::abs(value_of(gq[i]) * value_of(dq[i])) + std::abs(value_of(gp[i]) * value_of(dp[i]));
      cs = num / value_of(den);
    }
    if (sq && sp)
      for (int i = 0; i < n; ++i) {
        (*sq)[i] = std::abs(value_of(gq[i])) + cs * std::abs(value_of(dq[i]));
        (*sp)[i] = std::abs(value_of(gp[i])) + cs * std::abs(value_of(dp[i]));
      }
  }

  template <class T>
  void residual(const Vec<T, ny>& y, const Vec<T, nl>&, Vec<T, ny>* r, Vec<double, ny>* terms) const {
    const Vec<T, n> q1 = y.template head<n>(), p1 = y.template segment<n>(n);
    const Vec<T, m> lambda = y.template tail<m>();
    Vec<T, n> Dq, Dp;
    VecN sq, sp;
    discrete_gradient(q1, p1, &Dq, &Dp, &sq, &sp);
    const Vec<T, n> qb = cst<T>(0.5) * (q0.template cast<T>() + q1);
    const Mat<T, m, n> Wb = sys.template omega<T>(qb);
    const Vec<T, n> fc = Wb.transpose() * lambda;
    for (int i = 0; i < n; ++i) {
      (*r)[i] = q1[i] - cst<T>(q0[i]) - cst<T>(h) * Dp[i];                        // (q1 - q0)/h = gradbar_p H
      (*r)[n + i] = p1[i] - cst<T>(p0[i]) + cst<T>(h) * (Dq[i] - fc[i]);          // (p1 - p0)/h = -gradbar_q H + omega^T lambda
      if (terms) {
        (*terms)[i] = std::abs(value_of(q1[i])) + std::abs(q0[i]) + std::abs(h) * sp[i];
        double fs = 0;
        for (int a = 0; a < m; ++a) fs += std::abs(value_of(Wb(a, i)) * value_of(lambda[a]));
        (*terms)[n + i] = std::abs(value_of(p1[i])) + std::abs(p0[i]) + std::abs(h) * (sq[i] + fs);
      }
    }
    for (int a = 0; a < m; ++a) {  // omega(qbar) gradbar_p H = 0
      T c = cst<T>(0.0);
      double cs = 0;
      for (int j = 0; j < n; ++j) {
        c += Wb(a, j) * Dp[j];
        cs += std::abs(value_of(Wb(a, j))) * sp[j];
      }
      (*r)[2 * n + a] = c;
      if (terms) (*terms)[2 * n + a] = cs;
    }
  }
};

// The stateful discrete-gradient stepper (stepper.hpp), lag 0.
template <class S>
class DiscreteGradientStepper {
 public:
  static constexpr int n = S::n, m = S::m;
  static constexpr int lag = 0;
  using VecN = Vec<double, n>;
  using VecM = Vec<double, m>;
  using Problem = DiscreteGradientProblem<S>;

  explicit DiscreteGradientStepper(const S& sys, SolverOptions options = {}) : sys_(sys), options_(options) {
    if constexpr (is_separable<S>::value) {
      // The passes are exact in the force where K = dF/dq is constant (F
      // affine in q: a quadratic potential), with Q where K is not zero.
      if (const auto K = constant_force_jacobian(sys_)) {
        affine_force_ = true;
        if ((K->array() != 0.0).any()) {
          K_ = *K;
          Minv_ = inverse_mass_matrix(sys_);
          // The Gauss-Seidel first pass (passes()).
          gs_ = constraint_force_misses_omega(sys_);
          omega_reads_ = omega_reads(sys_);
        }
      }
    }
  }
  // Do the passes see the force exactly (F affine in q; passes())?
  bool passes_exact_in_force() const { return affine_force_; }
  // Passes made since construction, those after a Gauss-Seidel first pass
  // included (tests/test_new_methods.cpp counts them).
  long passes_made() const { return passes_made_; }
  // Run the residual check on passes that settled by their move too (map();
  // off by default), and count: steps whose passes so settled, and of those,
  // steps the check did not accept unchanged (tests/test_new_methods.cpp;
  // the second count only on a check_settled_passes(true) stepper).
  void check_settled_passes(bool on) { check_settled_ = on; }
  long settled_by_move_steps() const { return settled_by_move_steps_; }
  long settled_checks_failed() const { return settled_checks_failed_; }
  const S& system() const { return sys_; }

  MethodTraits traits() const {
    MethodTraits t;
    t.order = 2;
    t.symmetric = true;
    t.symmetric_in_phase = true;
    t.holds_velocity_constraint = false;
    t.implicit = true;
    t.preserves_energy = true;
    return t;
  }

  void start(const VecN& q0, const VecN& v0) {
    q_ = q0;
    p_ = momentum(sys_, q0, v0);
    lambda_ = VecM::Zero();
    has_step_ = false;
    steps_ = 0;
  }

  // One step (q0, p0) -> (q1, p1); lambda holds the guess and gets the multiplier.
  StepSummary map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1, VecM* lambda) const {
    const Problem prob(sys_, h, q0, p0);
    // Guess: an explicit Stoermer-Verlet-like step with the last multiplier
    // (second order when lambda is), so Newton starts close.
    const auto explicit_guess = [&] {
      const VecN qh = q0 + 0.5 * h * velocity<S, double>(sys_, q0, p0);
      const VecN pg = p0 + h * (force<S, double>(sys_, qh, p0) + sys_.template omega<double>(qh).transpose() * *lambda);
      Vec<double, Problem::ny> y;
      y << qh + 0.5 * h * velocity<S, double>(sys_, qh, pg), pg, *lambda;
      return y;
    };
    // Except where the first pass is exact whatever its input (a quadratic
    // H, passes exact in the force, and a Gauss-Seidel first pass: the
    // particle at h >= 0.032; passes()): the guess is then only the point
    // at which that pass's frozen quantities are taken, and at z1 = z0
    // Gonzalez's correction is 0 with no energy to evaluate.  The passes
    // start from (q0, p0), and the explicit guess is made only if they do
    // not settle, for Newton (on the particle, at h = 0.4 to 10, they
    // always settled or stalled at round-off: no step took that path in
    // 1800 measured).  Measured side by side on the particle at h = 0.2:
    // bench_steps, min of 5 interleaved rounds, 139.9 -> 125.7 ns per step
    // (a scratch loop: 140-143 -> 119-120); the steps move by round-off
    // (issue 13).  Where: the passes exact in the force (h^2/2 >= 5e-4 with
    // the particle's default kx = ky = 1: h >= 0.032) and
    // Curvature::first_pass_exact.
    bool trivial_start = false;
    if constexpr (is_separable<S>::value) trivial_start = gs_ && curvature(h).first_pass_exact;
    Vec<double, Problem::ny> y;
    if (trivial_start)
      y << q0, p0, *lambda;
    else
      y = explicit_guess();
    // The passes' iterate is used only when they settle: an iterate they did
    // not settle is often already within newton()'s first test (16 eps of
    // the full scale), which it would accept without an iteration, and on
    // the robot's triple jump that left |E - E0| at 8e-10 over 10^4 steps
    // against 4e-11 from Newton's own iterations (which end far below that
    // test).
    bool settled = false;
    if constexpr (is_separable<S>::value) {
      settled_by_move_ = false;
      // The passes work on y itself, and a step they do not settle makes
      // the explicit guess again for Newton (the same values: a function of
      // q0, p0 and *lambda alone).  A copy of y for them, kept in case they
      // failed, cost a sixth of the particle's step: perf put 17 % of it in
      // map(), mostly at that copy and at the unpacking after it, loads of
      // 16 bytes from y just written by 8-byte stores (the store-to-load
      // forwarding stall of particle.hpp's omega, "Tried and dropped" in
      // experiments/speed_log.md).  Scratch, min of 3 x 10^6 steps at
      // h = 0.2 restarted every 10^3: particle 116 -> 95-100 ns, its triple
      // jump 360-371 -> 288-301, contact oscillator 310-323 -> 299-310, the
      // other scenes the same to the noise; every step bit for bit the same
      // (issue 13).
      settled = passes(prob, &y);
      if (!settled) y = explicit_guess();
      // Passes that ended on a plain pass settled by its move (no component
      // moved by more than 4 eps of the terms of its residual row) are a fixed
      // point of the step's equations to their rounding: the plain pass solves
      // them exactly with c, omega and F frozen at its input, and its output
      // is that input to 4 eps.  The residual check then only confirmed it:
      // measured over ~1.1 million such steps (every separable scene, h = 0.0125
      // to 0.8, both directions) it accepted every one unchanged, so it is
      // skipped there (a check_settled_passes(true) stepper still runs it:
      // tests/test_new_methods.cpp, SeparableTest.DiscreteGradientSettledPassesNeedNoCheck).
      // Not every one everywhere: over the 10^6 composed steps of the long-horizon
      // study the contact oscillator's discrete gradient + triple jump and
      // + order 6 moved by round-off without it (experiments/speed_log.md, "What moved").
      // Measured side by side at h = 0.2 (bench_steps, min of 3 interleaved
      // rounds): particle 182.6 -> 151.1 ns, contact oscillator 397 -> 353,
      // robot 1402 -> 1338.  A step so accepted reports no evaluation and relative_residual 0
      // (not evaluated).  Passes that settled by stalling at round-off still
      // go to the check, as does every step when the tolerance asked for is
      // below the check's own round-off test (16 eps: the check, not the
      // passes, knows whether a residual meets it) (issue 13).
      // All of this sits under the separable branch, and the test's
      // bookkeeping (a copy of the iterate, a comparison) runs only on a
      // check_settled_passes(true) stepper.  With both on the common path
      // 3ee564d's session measured +15 % per step on the non-separable
      // contact_oscillator_nr, whose code path this never touches, and put
      // it down to codegen; c9b6251's did not reproduce it on its host
      // (experiments/speed_log.md, "What made steps faster").
      if (settled && settled_by_move_) {
        ++settled_by_move_steps_;
        if (check_settled_) {
          const Vec<double, Problem::ny> y_settled = y;
          Vec<double, 0> none;
          StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&y, &none, true);
          if (!s.ok() || s.jacobians > 0 || !(y.array() == y_settled.array()).all()) ++settled_checks_failed_;
          if (s.ok()) unpack(y, q1, p1, lambda);
          return s;
        }
        if (options_.tolerance >= 16 * std::numeric_limits<double>::epsilon()) {
          unpack(y, q1, p1, lambda);
          StepSummary s;
          s.status = SolveStatus::kConverged;
          return s;
        }
      }
    }
    Vec<double, 0> none;
    StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&y, &none, settled);
    if (s.ok()) unpack(y, q1, p1, lambda);
    return s;
  }

  static void unpack(const Vec<double, Problem::ny>& y, VecN* q1, VecN* p1, VecM* lambda) {
    *q1 = y.template head<n>();
    *p1 = y.template segment<n>(n);
    *lambda = y.template tail<m>();
  }

  // Fixed-point passes of the step's equations from y = (q1, p1, lambda), for
  // a separable system (V linear in p, F independent of p; issue 13).  A
  // pass freezes qbar (in F and omega) and Gonzalez's correction c dz at the
  // current iterate; the equations are then linear in (p1, lambda) and
  // explicit in q1:
  //     p1 = p0 - h (Dq - W^T lambda),  Dq = -F(qbar) + c dq,  W = omega(qbar)
  //     W (V((p0 + p1)/2) + c dp) = 0   (m equations in lambda: V is linear)
  //     q1 = q0 + h (V((p0 + p1)/2) + c dp).
  // At a fixed point every frozen quantity has its true value, so it is the
  // step's solution.  Each pass shrinks the error by a factor O(h) (measured:
  // 0.02-0.05 at h = 0.2, 1e-4 at h = 0.0125, on the paper's scenes and the
  // oscillators).  Where F is affine in q (a quadratic potential, K = dF/dq
  // constant: the particle), F(qbar) is not frozen but exact,
  //     F(qbar') = F(qbar) + K (qbar' - qbar),  qbar' = (q0 + q1')/2,
  // which with q1' = q0 + h (M^-1 (p0 + p1')/2 + c dp) makes the first two
  // lines linear in (p1', lambda) through Q = (I - (h^2/4) K M^-1)^-1; on the
  // particle the constraint row then reads a y that is exact after one pass,
  // and the passes settle in three (at h = 0.2, nine before; at h = 0.4 they
  // used to be mixed or give up on 19 % of the steps).  Settled, they hand
  // over to the plain passes, which settle at once (below).
  //   Gauss-Seidel first pass: where, besides, the constraint force misses
  // the coordinates omega reads (constraint_force_misses_omega; rows of
  // M^-1 Q W^T zero there, checked on the pass's own matrix), those
  // coordinates of q1' do not depend on lambda, so the first curved pass
  // takes them, q1'_j = q0_j + h (M^-1 (p0 + Q b)/2 + c dp)_j, before it
  // evaluates W = omega(qbar).  With H quadratic (K constant, M constant)
  // Gonzalez's c is zero up to its rounding whatever the iterate, so that
  // pass is exact, not the second: it hands over to the plain passes at
  // once, which confirm it (one pass where they settle) before the residual
  // check, two passes a step on the particle instead of four (three curved,
  // one plain).  Measured side by side in a scratch run (particle, ns per
  // step, min of 15, before -> after): h = 0.2 320 -> 230, h = 0.05
  // 343 -> 239, the triple jump at h = 0.2 1021 -> 698 (issue 13).  Being
  // exact from any input, that pass starts from z1 = z0 (map()), where c is
  // 0 without an energy evaluation.
  //   Returns true (settled: the solve starts with the residual
  // check, NewtonSolver::solve) when a pass moves no component by more than
  // 4 eps of the terms it is made of, or stops contracting (by 1/2) within
  // 1e-10 of the state's size: at round-off the iterates wander in a cloud
  // (lambda is set only to eps |H| / |dz|^2 through Gonzalez's c, and moves
  // p by h omega^T lambda; measured 5e-14 at h = 0.4 / 2^9 on the particle),
  // which the check judges.  Passes whose measured contraction predicts
  // that they will not settle within kPasses are mixed (Anderson mixing,
  // below).  Measured in one run (ns per step, before the mixing and the
  // early give-up -> with them, best of two): h = 0.4 particle 3670 -> 1390,
  // chaotic oscillator 5700 -> 1650, sleigh 3850 -> 950, contact oscillator
  // 1120 -> 750, robot 5400 -> 5220; h = 0.2 sleigh 2750 -> 970 (its passes
  // used to run out, and Newton took 4 iterations), robot 2330 -> 1740
  // (Newton iterations 0.64 -> 0.09 per step); h = 0.1 sleigh 1080 -> 750
  // (12 -> 6 passes); elsewhere at h <= 0.2 the passes are (almost) never
  // mixed and cost the same to the noise (+-7 %; the particle at h = 0.2
  // +21 % in that run with the same 9.04 passes per step).
  // False when a pass contracts by less than 1/2
  // above that (diverging: Newton takes over from the explicit start), when
  // the mixed passes still predict more than kPasses in all, or after kPasses.
  static constexpr int kPasses = 12, kPredict = 3;
  static constexpr double kSettled = 4 * std::numeric_limits<double>::epsilon();
  static constexpr double kStall = 1e-10;
  static constexpr double kMaxGamma = 4;
  bool passes(const Problem& prob, Vec<double, Problem::ny>* y, bool allow_curved = true) const {
    const double h = prob.h;
    const VecN& q0 = prob.q0;
    const VecN& p0 = prob.p0;
    VecN q1 = y->template head<n>(), p1 = y->template segment<n>(n);
    const double size = 1 + q0.cwiseAbs().maxCoeff() + p0.cwiseAbs().maxCoeff();
    double last_move = std::numeric_limits<double>::infinity();
    // Anderson mixing of depth 1 (see above): the last pass's output g and
    // its move f = g - x.
    Vec<double, 2 * n> f_prev, g_prev;
    int mix_from = -1;  // the pass from which the passes are mixed (-1: not)
    // F affine in q (see the constructor): Q = (I - (h^2/4) K M^-1)^-1 and
    // M^-1 Q, kept for the last two step sizes (the triple jump and Suzuki's
    // composition alternate between two: the particle's triple jump cost
    // 956-972 ns per step with one kept, 926-944 with two, in a scratch run).
    // Only where a plain pass gains less than ~2000 (its factor is about
    // rho = (h^2/4) |K M^-1|): below, the plain passes settle in about as
    // many passes as the curved ones and the hand-over (measured on the
    // particle: h = 0.025, rho = 3e-4, the same 426 ns per step either way;
    // h = 0.0125: 371 ns plain, 438 curved; h = 0.05: 475 plain, 390 curved).
    if (K_) curvature(h);
    const bool curved = allow_curved && K_ && curv_.current().ok;
    const Mat<double, n, n>& Q = curv_.current().Q;
    const Mat<double, n, n>& MQ = curv_.current().MQ;
    // Does the constraint force M^-1 Q W^T lambda miss every coordinate omega reads?
    const auto misses_omega = [this](const Mat<double, n, m>& moved) {
      for (int j = 0; j < n; ++j)
        if (omega_reads_[j] && !(moved.row(j).array() == 0.0).all()) return false;
      return true;
    };
    for (int pass = 0; pass < kPasses; ++pass) {
      // Dq = -F(qbar) + c dq and the frozen c dp, with the sizes sq, sp of
      // the residual's rows (DiscreteGradientProblem::discrete_gradient).
      VecN Dq, Dp, sq, sp;
      double c = 0;
      prob.template discrete_gradient<double>(q1, p1, &Dq, &Dp, &sq, &sp, &c);
      ++passes_made_;
      const VecN qb = 0.5 * (q0 + q1), cp = c * (p1 - p0);
      Mat<double, m, n> W = sys_.template omega<double>(qb);
      bool exact = false;  // a Gauss-Seidel first pass (above)
      VecM l = VecM::Zero();
      VecN p1n, q1n;
      if (curved) {
        // F(qbar') = F(qbar) + K (qbar' - qbar) exactly, qbar' = (q0 + q1')/2
        // = d0 + qbar + (h/4) M^-1 p1', d0 = q0 + (h/2) c dp + (h/4) M^-1 p0 - qbar;
        // then p1' = Q b + h Q W^T lambda, b = p0 - h Dq + h K d0, and the
        // constraint W (M^-1 (p0 + p1')/2 + c dp) = 0 gives lambda.
        const VecN d0 = q0 + (0.5 * h) * cp + (0.25 * h) * (Minv_ * p0) - qb;
        const VecN b = p0 - h * Dq + h * (*K_ * d0);
        const VecN Qb = Q * b;
        if constexpr (m > 0) {
          // V((p0 + p1')/2) + c dp without the constraint force's part.
          const VecN vfree = VecN(0.5 * (Minv_ * VecN(p0 + Qb))) + cp;
          Mat<double, n, m> MQWt = MQ * W.transpose();
          if (pass == 0 && gs_ && misses_omega(MQWt)) {
            VecN qg = q1;
            for (int j = 0; j < n; ++j)
              if (omega_reads_[j]) qg[j] = q0[j] + h * vfree[j];
            W = sys_.template omega<double>(VecN(0.5 * (q0 + qg)));
            MQWt = MQ * W.transpose();
            exact = misses_omega(MQWt);
          }
          const Mat<double, m, m> A = (0.5 * h) * (W * MQWt);
          l = -(A.inverse() * (W * vfree));
          p1n = Qb + h * (Q * (W.transpose() * l));
        } else {
          p1n = Qb;
        }
        q1n = q0 + h * (VecN(0.5 * (Minv_ * VecN(p0 + p1n))) + cp);
      } else {
        if constexpr (m > 0) {
          Mat<double, m, m> A;
          for (int a = 0; a < m; ++a) A.col(a) = W * velocity<S, double>(sys_, qb, VecN((0.5 * h) * W.row(a).transpose()));
          l = -(A.inverse() * (W * VecN(velocity<S, double>(sys_, qb, VecN(p0 - (0.5 * h) * Dq)) + cp)));
        }
        p1n = p0 - h * (Dq - W.transpose() * l);
        q1n = q0 + h * (velocity<S, double>(sys_, qb, VecN(0.5 * (p0 + p1n))) + cp);
      }
      if (!(all_finite(q1n) && all_finite(p1n) && all_finite(l))) return false;
      const double move = std::max((q1n - q1).cwiseAbs().maxCoeff(), (p1n - p1).cwiseAbs().maxCoeff());
      // Settled: no component moved by more than 4 eps of the terms that make
      // it (those of the residual's rows, DiscreteGradientProblem::residual).
      const VecN fs = W.cwiseAbs().transpose() * l.cwiseAbs();
      const VecN bound_q = kSettled * (q0.cwiseAbs() + q1n.cwiseAbs() + std::abs(h) * sp),
                 bound_p = kSettled * (p0.cwiseAbs() + p1n.cwiseAbs() + std::abs(h) * (sq + fs));
      const bool fixed = ((q1n - q1).cwiseAbs() - bound_q).maxCoeff() <= 0 && ((p1n - p1).cwiseAbs() - bound_p).maxCoeff() <= 0;
      // No longer contracting: at round-off (the residual check judges) or diverging.
      if (!fixed && pass > 0 && !(move <= 0.5 * last_move)) {
        if (!(last_move <= kStall * size)) return false;
        return curved ? passes(prob, y, false) : true;  // (the plain passes end it: see below)
      }
      // Passes still needed at the contraction r = move / last_move just
      // measured: log(1 / excess) / log r.  More than are left
      // (kPasses - pass - 1) iff excess r^left > 1, tested without
      // logarithms (two per pass cost 10-15 % of a step at h = 0.2).  Then
      // the passes are mixed from here on (below).  The excess, not the move
      // against the state's size: the sleigh's passes crawl in a component
      // much smaller than the state, and against the state they looked as if
      // they would make it, ran out, and Newton took 4 iterations (h = 0.2).
      // If, two passes into the mixing, even the move against the state's
      // size (4 eps size / move < r^left, the lenient test: a give-up costs
      // a Newton solve, and at h = 0.4 mixed passes that fail the strict
      // test often settle) predicts more than kPasses, they give up (at
      // h = 0.4 unmixed passes contract by only ~0.1-0.4 and, without the
      // give-up, all ran before Newton did: particle 2.1 -> 4.1 us per step).
      // The test runs on the first kPredict passes and two passes into the
      // mixing only: on every pass its divisions and powers cost 5-30 % of
      // a step at h = 0.1-0.2, where it almost never fires.
      if (!fixed && pass > 0 && (mix_from < 0 ? pass <= kPredict : pass == mix_from + 2)) {
        const double r = move / last_move;
        double r_left = 1;
        for (int j = pass + 1; j < kPasses; ++j) r_left *= r;
        if (mix_from < 0) {
          // The excess: the largest move over its own bound (settled: <= 1).
          constexpr double tiny = std::numeric_limits<double>::min();  // a zero bound: 0 / tiny = 0
          const double excess = std::max((q1n - q1).cwiseAbs().cwiseQuotient(bound_q.cwiseMax(tiny)).maxCoeff(),
                                         (p1n - p1).cwiseAbs().cwiseQuotient(bound_p.cwiseMax(tiny)).maxCoeff());
          if (excess * r_left > 1) mix_from = pass;
        } else if (move * r_left > kSettled * size) {
          return false;
        }
      }
      last_move = move;
      *y << q1n, p1n, l;
      // Settled curved passes hand over to the plain ones, which then settle
      // at once (one pass, two at most): the curved passes' fixed point is the
      // step's solution, but their rounding is not that of the residual, and
      // ending on them left the energy drifting by ~0.5 ulp of H per step on
      // the particle at h = 0.2 (1.2e-10 over 10^6 steps, against 1.5e-11).
      // So does an exact Gauss-Seidel first pass, unconfirmed.
      if (fixed || exact) {
        if (!curved) settled_by_move_ = true;  // (a plain pass's fixed: map())
        return curved ? passes(prob, y, false) : true;
      }
      // The next input: the output g, or once the passes are found too slow,
      // g mixed with the last output,
      //     x' = g - gamma (g - g_prev),  gamma = <df, f> / <df, df>,  df = f - f_prev,
      // the secant step along the last two moves f = g - x (Anderson mixing
      // of depth 1; Walker & Ni, SIAM J. Numer. Anal. 49 (2011) 1715, type II
      // with m = 1).  It removes the slowest direction of the passes' linear
      // contraction, the one the sleigh's passes crawl along.  A |gamma| above
      // kMaxGamma (nearly parallel moves, at round-off) keeps g.  Only slow
      // passes are mixed: the mixing puts dot products and a division on the
      // passes' dependency chain, and mixing every pass made the fast ones
      // slower (particle at h = 0.2: 680 -> 940 ns per step) although it
      // saved 1.5 of their 9 passes; mixing those predicted to need more
      // than 8 cost the particle 660 -> 750 ns and the chaotic oscillator
      // 800 -> 1340 ns at h = 0.2.
      if (mix_from < 0) {
        q1 = q1n;
        p1 = p1n;
        continue;
      }
      Vec<double, 2 * n> g, f;
      g << q1n, p1n;
      f << q1n - q1, p1n - p1;
      Vec<double, 2 * n> x = g;
      if (pass > mix_from) {
        const Vec<double, 2 * n> df = f - f_prev;
        const double dd = df.squaredNorm();
        if (dd > 0) {
          const double gamma = df.dot(f) / dd;
          if (std::abs(gamma) <= kMaxGamma) x = g - gamma * (g - g_prev);
        }
      }
      f_prev = f;
      g_prev = g;
      q1 = x.template head<n>();
      p1 = x.template tail<n>();
    }
    return false;
  }

  StepSummary step(double h) {
    VecN q1, p1;
    VecM lambda = lambda_;
    StepSummary s = map(h, q_, p_, &q1, &p1, &lambda);
    ++steps_;
    if (s.ok() && !(all_finite(q1) && all_finite(p1))) {
      s.status = SolveStatus::kFailed;
      s.failure = FailureKind::kNonFinite;
      s.message = "non-finite state";
    }
    if (!s.ok()) {
      s.message = "discrete_gradient step " + std::to_string(steps_) + " did not converge: " + s.message;
      return s;
    }
    // The step's start and size, for its averaged constraint in sample().
    q_prev_ = q_;
    p_prev_ = p_;
    h_prev_ = h;
    has_step_ = true;
    q_ = q1;
    p_ = p1;
    lambda_ = lambda;
    return s;
  }

  // Point k: q_k, v_k = V(q_k, p_k), p_k, the multiplier and the averaged
  // constraint omega(qbar) gradbar_p H of the step that arrived at k (0 at
  // k = 0; zero to round-off).  It is evaluated here, when a point is
  // recorded, not in every step (as the DLA and mp06 do theirs): a second
  // discrete gradient, H(q_k, p_k) and omega per step, 3-7 % of the step at
  // h = 0.2 in a scratch run (issue 13).  The same arithmetic either way.
  void sample(Sample<n, m>* s) const {
    s->has_p = true;
    s->q = q_;
    s->v = velocity<S, double>(sys_, q_, p_);
    s->p = p_;
    s->lambda = lambda_;
    s->discrete_constraint = VecM::Zero();
    if (has_step_) {
      const Problem prob(sys_, h_prev_, q_prev_, p_prev_);
      VecN Dq, Dp;
      prob.template discrete_gradient<double>(q_, p_, &Dq, &Dp);
      s->discrete_constraint = sys_.template omega<double>(VecN(0.5 * (q_prev_ + q_))) * Dp;
    }
  }

  Vec<double, 2 * n> phase() const {
    Vec<double, 2 * n> z;
    z << q_, p_;
    return z;
  }

 private:
  S sys_;
  SolverOptions options_;
  VecN q_ = VecN::Zero(), p_ = VecN::Zero();
  VecM lambda_ = VecM::Zero();
  long steps_ = 0;
  // The last successful step: its start (q, p) and size (sample()).
  VecN q_prev_ = VecN::Zero(), p_prev_ = VecN::Zero();
  double h_prev_ = 0;
  bool has_step_ = false;
  // F affine in q (passes()): K = dF/dq, M^-1, and Q, M^-1 Q for a step size (curv_).
  bool affine_force_ = false;
  std::optional<Mat<double, n, n>> K_;  // when not 0
  Mat<double, n, n> Minv_ = Mat<double, n, n>::Zero();
  // The Gauss-Seidel first pass (passes()): constraint_force_misses_omega, and omega_reads.
  bool gs_ = false;
  std::array<bool, n> omega_reads_{};
  mutable long passes_made_ = 0;
  // Did the last passes end on a plain pass settled by its move (map())?
  mutable bool settled_by_move_ = false;
  bool check_settled_ = false;
  mutable long settled_by_move_steps_ = 0, settled_checks_failed_ = 0;
  struct Curvature {
    Mat<double, n, n> Q = Mat<double, n, n>::Zero(), MQ = Mat<double, n, n>::Zero();
    bool ok = false;
    // The first pass is a Gauss-Seidel pass exact from any input (map()):
    // gs_ says that M^-1 W^T misses the coordinates omega reads; M^-1 Q W^T
    // does too where each such coordinate j has one entry in its row of
    // M^-1, at column k, and its row of M^-1 Q none but there (then gs_
    // makes W's column k zero, and with it (M^-1 Q W^T)_j).  A
    // sufficient test, not a necessary one: a system it misses starts its
    // passes from the explicit guess, as before.
    bool first_pass_exact = false;
  };
  mutable StepSizeCache<Curvature> curv_;  // current(): this step's
  // Q and M^-1 Q for step size h, kept for the last two step sizes (K_
  // set; passes() and map()).
  const Curvature& curvature(double h) const {
    curv_.at(h, [this](double hh) {
      Curvature cv;
      const Mat<double, n, n> hKM = (0.25 * hh * hh) * (*K_ * Minv_);
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
    });
    return curv_.current();
  }
};

// The method table's entry (methods.hpp): "discrete_gradient", symmetric, so composable.
struct DiscreteGradientMethod {
  static constexpr const char* name = "discrete_gradient";
  static constexpr bool uses_discretization = false;
  static bool symmetric(const MethodSpec&) { return true; }  // so it composes (composition.hpp)
  static constexpr bool reports_p = true;
  template <class S, class F>
  static auto with_stepper(const S& sys, const MethodSpec& spec, F&& f) {
    SolverOptions opt;
    opt.tolerance = spec.tolerance;
    return with_composition(DiscreteGradientStepper<S>(sys, opt), spec.composition, f);
  }
  static std::vector<StudyEntry> study_entries() {
    return {{spec_of(name)},
            {spec_of(name, "triple_jump")},
            {spec_of(name, "suzuki5"), "variant"},
            {spec_of(name, "order6"), "variant"}};
  }
};

}  // namespace nhi
