// Symmetry and reversibility of a method's one-step map, measured.
//
// Symmetry (self-adjointness): Phi_{-h} o Phi_h = id, a step of h then one of
// -h returns to the start.
// Reversibility under the velocity flip rho(q, v) = (q, -v):
//   Phi_h o rho o Phi_h = rho,
// the property Modin & Verdier ("What makes nonholonomic integrators work?",
// Numer. Math. 145, 2020, §2) show gives bounded energy and first integrals on
// reversible integrable nonholonomic systems.  A symmetric method is
// rho-reversible when its map commutes with rho as the continuous flow's does;
// on a system whose Lagrangian is not even in v (contact_oscillator_nr's gauge
// term sin z * zdot) a symmetric method need not be.
//
// Defect from z0 = (q0, v0) on the constraint:
//   z1 = Phi_h(z0),  z2 = Phi_h(rho z1),  defect = |rho z2 - z0|
// rho is applied in the method's own variables through its start: the newest
// point (q1, p1) is read as (q1, V(q1, p1)) (V the inverse Legendre map) and a
// fresh stepper starts from (q1, -V(q1, p1)), i.e. from the momentum
// dL/dv(q1, -v1).  Both defects are reported in q and in (q, v), relative to
// 1 + max |z0| + max |z1|.  The DLA is a map of (q, p mod omega(q)^T) (dla.hpp):
// its p carries the constraint force, so for it only the q defect is a
// statement about the map (MethodTraits::symmetric_in_phase = false).
#pragma once

#include <algorithm>
#include <memory>

#include "nhi/methods/methods.hpp"
#include "nhi/roles/hamiltonian.hpp"
#include "nhi/runner/run.hpp"

namespace nhi {

struct MapDefects {
  double symmetry_q = 0, symmetry_phase = 0;            // |Phi_{-h} Phi_h z0 - z0|
  double reversibility_q = 0, reversibility_phase = 0;  // |rho Phi_h rho Phi_h z0 - z0|
  bool ok = true;                                       // every step converged
};

// v with omega(q) v = 0 nearest to w (least squares).
template <class S>
Vec<double, S::n> project_to_constraint(const S& sys, const Vec<double, S::n>& q, const Vec<double, S::n>& w) {
  if constexpr (S::m == 0) {
    return w;
  } else {
    const Mat<double, S::m, S::n> W = sys.template omega<double>(q);
    const Mat<double, S::m, S::m> G = W * W.transpose();
    return w - W.transpose() * G.ldlt().solve(W * w);
  }
}

template <class S>
MapDefects map_defects(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                       double h) {
  constexpr int n = S::n;
  const bool momentum = method_flags(spec.kind).reports_p;  // phase() is (q, p), else (q, v)
  auto as_qv = [&](const Vec<double, 2 * n>& z) {
    Vec<double, 2 * n> out = z;
    if (momentum) {
      const Vec<double, n> q = z.template head<n>(), p = z.template tail<n>();
      out.template tail<n>() = velocity(sys, q, p);
    }
    return out;
  };
  MapDefects d;
  Vec<double, 2 * n> z0;
  z0 << q0, v0;
  // Phi_h, then Phi_{-h} in the same stepper.
  const auto st = make_stepper(sys, spec);
  st->start(q0, v0);
  d.ok = st->step(h).ok();
  const Vec<double, 2 * n> z1 = as_qv(st->phase());
  d.ok = st->step(-h).ok() && d.ok;
  const Vec<double, 2 * n> back = as_qv(st->phase());
  // rho, Phi_h in a fresh stepper, rho.
  const auto rev = make_stepper(sys, spec);
  rev->start(z1.template head<n>(), -z1.template tail<n>());
  d.ok = rev->step(h).ok() && d.ok;
  Vec<double, 2 * n> z2 = as_qv(rev->phase());
  z2.template tail<n>() = -z2.template tail<n>();
  const double scale = 1.0 + z0.cwiseAbs().maxCoeff() + z1.cwiseAbs().maxCoeff();
  d.symmetry_q = (back - z0).template head<n>().cwiseAbs().maxCoeff() / scale;
  d.symmetry_phase = (back - z0).cwiseAbs().maxCoeff() / scale;
  d.reversibility_q = (z2 - z0).template head<n>().cwiseAbs().maxCoeff() / scale;
  d.reversibility_phase = (z2 - z0).cwiseAbs().maxCoeff() / scale;
  return d;
}

}  // namespace nhi
