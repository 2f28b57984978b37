// The bodies of DiscreteGradientStepper's members (discrete_gradient.hpp):
// the construction, start, map, the fixed-point passes, step, sample and
// phase, which run the step's passes, solve and autodiff.  Included by the
// library's explicit instantiations (lib/src/methods/discrete_gradient.cpp), which compile
// them once for every registered system, and by code that instantiates
// DiscreteGradientStepper for a system outside the registry (a test's own
// system); code that includes only discrete_gradient.hpp links to the
// library's instances.
#pragma once

#include "nhi/discrete_gradient.hpp"

namespace nhi {

template <class S>
DiscreteGradientStepper<S>::DiscreteGradientStepper(const S& sys, SolverOptions options, bool endpoint)
    : sys_(sys), options_(options), endpoint_(endpoint) {
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

template <class S>
void DiscreteGradientStepper<S>::start(const VecN& q0, const VecN& v0) {
  q_ = q0;
  p_ = momentum(sys_, q0, v0);
  lambda_ = VecM::Zero();
  has_step_ = false;
  steps_ = 0;
  memory_ = {};
  memory_next_ = 0;
}

template <class S>
StepSummary DiscreteGradientStepper<S>::map(double h, const VecN& q0, const VecN& p0, VecN* q1, VecN* p1,
                                            VecM* lambda) const {
  const Problem prob(sys_, h, q0, p0, endpoint_);
  // Guess: an explicit Stoermer-Verlet-like step with the last multiplier
  // (second order when lambda is), so Newton starts close.
  const auto explicit_guess = [&] {
    const VecN qh = q0 + 0.5 * h * velocity<S, double>(sys_, q0, p0);
    const VecN pg = p0 + h * (force<S, double>(sys_, qh, p0) + sys_.template omega<double>(qh).transpose() * *lambda);
    Vec<double, Problem::ny> y;
    y << qh + 0.5 * h * velocity<S, double>(sys_, qh, pg), pg, *lambda;
    return y;
  };
  if (endpoint_) {
    // Newton from the midpoint form's step where its passes settle (a
    // separable system), which is O(h^3) from this one's: about one Newton
    // iteration fewer than from the explicit guess.  Else (the passes did not
    // settle, or there are none) from the explicit guess.
    Vec<double, Problem::ny> y = explicit_guess();
    if constexpr (is_separable<S>::value) {
      Vec<double, Problem::ny> z = y;
      if (passes(Problem(sys_, h, q0, p0), &z)) y = z;
    }
    // Plain Newton (a fresh Jacobian every iteration), not the chord steps;
    // then one more update from the accepted iterate (a second solve() from
    // it takes that update with no iteration counted; not when following
    // roots, where solve() would continue again): the energy identity holds
    // only as well as the rows are solved, and Newton accepts them at 16 eps
    // of their scale, which leaves several eps of the energy's terms a step.
    SolverOptions newton = options_;
    newton.refresh_ratio = 0;
    const NewtonSolver<Problem> solver(prob, newton);
    Vec<double, 0> none;
    StepSummary s = solver.solve(&y, &none);
    if (s.ok() && !newton.follows_roots()) {
      Vec<double, Problem::ny> polished = y;
      const StepSummary p = solver.solve(&polished, &none);
      s.evaluations += p.evaluations;
      s.jacobians += p.jacobians;
      s.iterations += p.iterations;
      if (p.ok()) y = polished;
    }
    if (s.ok()) unpack(y, q1, p1, lambda);
    return s;
  }
  return map_midpoint(prob, explicit_guess, q1, p1, lambda);
}

template <class S>
template <class Guess>
StepSummary DiscreteGradientStepper<S>::map_midpoint(const Problem& prob, const Guess& explicit_guess, VecN* q1,
                                                     VecN* p1, VecM* lambda) const {
  const double h = prob.h;
  const VecN& q0 = prob.q0;
  const VecN& p0 = prob.p0;
  // Except where the first pass is exact whatever its input (a quadratic
  // H, passes exact in the force, and a Gauss-Seidel first pass: the
  // particle at h >= 0.032; passes()): the guess is then only the point
  // at which that pass's frozen quantities are taken, and at z1 = z0
  // Gonzalez's correction is 0 with no energy to evaluate.  The passes
  // start from (q0, p0), and the explicit guess is made only if they do
  // not settle, for Newton (on the particle, at h = 0.4 to 10, they
  // settle or stall at round-off).  Where: the passes exact in the force
  // (h^2/2 >= 5e-4 with the particle's default kx = ky = 1: h >= 0.032)
  // and Curvature::first_pass_exact.
  bool trivial_start = false;
  if constexpr (is_separable<S>::value) trivial_start = gs_ && curvature(h).first_pass_exact;
  Vec<double, Problem::ny> y;
  if (trivial_start)
    y << q0, p0, *lambda;
  else
    y = explicit_guess();
  // The passes' iterate is used only when they settle: an iterate they did
  // not settle is often already within newton()'s first test (16 eps of
  // the full scale), which it would accept without an iteration, leaving
  // a larger energy error than Newton's own iterations, which end far
  // below that test (the robot's triple jump).
  bool settled = false;
  if constexpr (is_separable<S>::value) {
    settled_by_move_ = false;
    // The passes work on y itself, and a step they do not settle makes
    // the explicit guess again for Newton (the same values: a function of
    // q0, p0 and *lambda alone).  A copy of y for them, kept in case they
    // failed, would be a sizeable share of the particle's step: the copy and
    // the unpacking after it load 16 bytes from y just written by 8-byte
    // stores (a store-to-load forwarding stall, as in particle.hpp's omega).
    settled = passes(prob, &y);
    if (!settled) y = explicit_guess();
    // Passes that ended on a plain pass settled by its move (no component
    // moved by more than 4 eps of the terms of its residual row) are a fixed
    // point of the step's equations to their rounding: the plain pass solves
    // them exactly with c, omega and F frozen at its input, and its output
    // is that input to 4 eps.  The residual check would only confirm it,
    // accepting it unchanged, so it is skipped there (a
    // check_settled_passes(true) stepper still runs it:
    // tests/test_discrete_gradient.cpp, DiscreteGradientTest.DiscreteGradientSettledPassesNeedNoCheck).
    // Not on every step everywhere: over the 10^6 composed steps of the
    // long-horizon study the check would move the contact oscillator's
    // discrete gradient + triple jump and + order 6 by round-off.
    // A step so accepted reports no evaluation and relative_residual 0
    // (not evaluated).  Passes that settled by stalling at round-off still
    // go to the check, as does every step when the tolerance asked for is
    // below the check's own round-off test (16 eps: the check, not the
    // passes, knows whether a residual meets it).
    // All of this sits under the separable branch, and the test's
    // bookkeeping (a copy of the iterate, a comparison) runs only on a
    // check_settled_passes(true) stepper, so that neither is on the common
    // path.
    if (settled && settled_by_move_ && !options_.continuation) {
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
        StepSummary s;
        s.status = SolveStatus::kConverged;
        if (options_.root_check) {  // continued from the explicit guess, Newton's start (before unpack sets *lambda)
          Vec<double, 0> none;
          s.root = NewtonSolver<Problem>(prob, options_).check_root(y, none, explicit_guess(), none);
        }
        unpack(y, q1, p1, lambda);
        return s;
      }
    }
  }
  Vec<double, 0> none;
  StepSummary s = NewtonSolver<Problem>(prob, options_).solve(&y, &none, settled);
  if (s.ok()) unpack(y, q1, p1, lambda);
  return s;
}

// Fixed-point passes of the step's equations from y = (q1, p1, lambda), for
// a separable system (V linear in p, F independent of p).  A
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
// and the passes settle in three at h = 0.2.  Settled, they hand
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
// one plain).  Being exact from any input, that pass starts from
// z1 = z0 (map()), where c is 0 without an energy evaluation.
//   Returns true (settled: the solve starts with the residual
// check, NewtonSolver::solve) when a pass moves no component by more than
// 4 eps of the terms it is made of, or stops contracting (by 1/2) within
// 1e-10 of the state's size: at round-off the iterates wander in a cloud
// (lambda is set only to eps |H| / |dz|^2 through Gonzalez's c, and moves
// p by h omega^T lambda; measured 5e-14 at h = 0.4 / 2^9 on the particle),
// which the check judges.  Passes whose measured contraction predicts
// that they will not settle within kPasses are mixed (Anderson mixing,
// below), which spares the slow cases (large h, the sleigh) most of their
// passes and Newton iterations; at h <= 0.2 the passes are almost never
// mixed.
// False when a pass contracts by less than 1/2
// above that (diverging: Newton takes over from the explicit start), when
// the mixed passes still predict more than kPasses in all, or after kPasses.
template <class S>
bool DiscreteGradientStepper<S>::passes(const Problem& prob, Vec<double, Problem::ny>* y, bool allow_curved) const {
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
  // composition alternate between two).
  // Only where a plain pass gains less than ~2000 (its factor is about
  // rho = (h^2/4) |K M^-1|): below, the plain passes settle in about as
  // many passes as the curved ones and the hand-over.
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
        for (int a = 0; a < m; ++a)
          A.col(a) = W * velocity<S, double>(sys_, qb, VecN((0.5 * h) * W.row(a).transpose()));
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
    const bool fixed =
        ((q1n - q1).cwiseAbs() - bound_q).maxCoeff() <= 0 && ((p1n - p1).cwiseAbs() - bound_p).maxCoeff() <= 0;
    // No longer contracting: at round-off (the residual check judges) or diverging.
    if (!fixed && pass > 0 && !(move <= 0.5 * last_move)) {
      if (!(last_move <= kStall * size)) return false;
      return curved ? passes(prob, y, false) : true;  // (the plain passes end it: see below)
    }
    // Passes still needed at the contraction r = move / last_move just
    // measured: log(1 / excess) / log r.  More than are left
    // (kPasses - pass - 1) iff excess r^left > 1, tested without
    // logarithms (two per pass would be a noticeable share of a step).  Then
    // the passes are mixed from here on (below).  The excess, not the move
    // against the state's size: the sleigh's passes crawl in a component
    // much smaller than the state, and against the state they look as if
    // they would make it, run out, and leave Newton several iterations.
    // If, two passes into the mixing, even the move against the state's
    // size (4 eps size / move < r^left, the lenient test: a give-up costs
    // a Newton solve, and at h = 0.4 mixed passes that fail the strict
    // test often settle) predicts more than kPasses, they give up (at
    // h = 0.4 unmixed passes contract by only ~0.1-0.4, and without the
    // give-up all of them would run before Newton does).
    // The test runs on the first kPredict passes and two passes into the
    // mixing only: on every pass its divisions and powers would be a
    // noticeable share of a step at h = 0.1-0.2, where it almost never fires.
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
    // ending on them would leave the energy drifting by ~0.5 ulp of H per
    // step (the particle at h = 0.2).
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
    // passes' dependency chain, which makes fast passes slower even where
    // it saves one or two of them.
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

template <class S>
StepSummary DiscreteGradientStepper<S>::step(double h) {
  VecN q1, p1;
  VecM lambda = lambda_;
  // The endpoint variant starts from the multiplier of the last steps of the
  // same h (a composition's stages each have their own), extrapolated from
  // the last two: second order in the explicit guess's momentum.
  StepMemory* mem = nullptr;
  if (endpoint_) {
    for (StepMemory& e : memory_)
      if (e.count > 0 && e.h == h) mem = &e;
    if (mem) lambda = mem->count >= 2 ? VecM(2.0 * mem->last - mem->prev) : mem->last;
  }
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
  if (endpoint_) {
    if (!mem) {
      mem = &memory_[memory_next_];
      memory_next_ = (memory_next_ + 1) % int(memory_.size());
      *mem = StepMemory{h, lambda, lambda, 0};
    }
    mem->prev = mem->last;
    mem->last = lambda;
    ++mem->count;
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

template <class S>
void DiscreteGradientStepper<S>::sample(Sample<n, m>* s) const {
  s->has_p = true;
  s->q = q_;
  s->v = velocity<S, double>(sys_, q_, p_);
  s->p = p_;
  s->lambda = lambda_;
  s->discrete_constraint = VecM::Zero();
  if (endpoint_) {
    s->discrete_constraint = sys_.template omega<double>(q_) * s->v;
  } else if (has_step_) {
    const Problem prob(sys_, h_prev_, q_prev_, p_prev_);
    VecN Dq, Dp;
    prob.template discrete_gradient<double>(q_, p_, &Dq, &Dp);
    s->discrete_constraint = sys_.template omega<double>(VecN(0.5 * (q_prev_ + q_))) * Dp;
  }
}

template <class S>
auto DiscreteGradientStepper<S>::phase() const -> Vec<double, 2 * n> {
  Vec<double, 2 * n> z;
  z << q_, p_;
  return z;
}

}  // namespace nhi

// The library compiles DiscreteGradientStepper for every registered system (lib/src/methods/discrete_gradient.cpp):
// where this body is included, those instances are declared, not compiled again.
#include "nhi/systems/registry.hpp"
// clang-format off
#define NHI_EXTERN_INSTANCES_(S) extern template class nhi::DiscreteGradientStepper<nhi::S>;
// clang-format on
NHI_REGISTERED_SYSTEMS(NHI_EXTERN_INSTANCES_)
#undef NHI_EXTERN_INSTANCES_
