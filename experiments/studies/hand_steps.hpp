// Hand-reduced steps: one method on one scene, written out by hand with every
// structure of that scene used, as a floor for what the library's generic
// solve of the same equations could cost (bench_steps measures both in one
// run; tests/test_mp06.cpp checks that they are the same map to
// round-off).  Not library code: nothing here is generic.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace floors {

// McLachlan & Perlmutter's mp06 step (eq. 4.18, lib/nhi/methods/mp06/mp06.hpp) on the
// non-reversible contact oscillator (lib/nhi/systems/contact_oscillator_nr.hpp):
//   L' = 1/2 |v|^2 - U(q) + sin(z) zd,   U = 1/2 |q|^2 + eps/2 x^2 z^2,
//   omega(q) = (1, 0, y),  V(q, p) = p - (0, 0, sin z),
//   F(q, p) = -grad U(q) + (0, 0, cos(z) V_z(q, p)).
// With q_half = q0 + (h/2) V(q0, p0) explicit, F(q_half, p) is affine in p,
// so the momentum equation gives p1y explicitly and p1x, p1z affine in lambda:
//   p1x = bx + h lambda,   (1 - (h/2) cos z_half) p1z = bz + h y_half lambda,
//   bx = p0x - h U_x,   bz = p0z - h U_z + (h/2) cos(z_half) (p0z - 2 sin z_half)
// (U at q_half).  q1 = q_half + (h/2) V(q1, p1) gives x1, y1 explicitly and
// z1 = z_half + (h/2) w with w = v1z = p1z - sin z1.  The constraint
// v1x + y1 w = 0 gives p1x = -y1 w, which fixes lambda, and what is left is one
// equation in w:
//   g(w) = (w + sin(z_half + h w / 2)) (1 - (h/2) cos z_half) - bz + y_half (y1 w + bx) = 0,
// solved by Newton with g' written out: one sin and one cos per iteration.
// The start is the zero of g linearized at w = 0 (no new sin or cos; a start
// from the momentum equation with the last multiplier leaves the first
// Newton update at ~10 % of w, and takes more iterations).  The iteration
// stops when the Newton update is below 1e-9 relative, after which the error
// is of the order of its square (no residual is evaluated to confirm it,
// which the library's solve does): a floor, not a robust solver.  step()
// returns false if 20 iterations did not get there.
struct Mp06ContactOscillatorNR {
  double epsilon = 0.3;
  long iterations = 0;  // summed over steps

  // *lambda: the step's multiplier on return (the start does not read it).
  bool step(double h, const Eigen::Vector3d& q0, const Eigen::Vector3d& p0, Eigen::Vector3d* q1, Eigen::Vector3d* p1,
            double* lambda) {
    const double xh = q0[0] + 0.5 * h * p0[0], yh = q0[1] + 0.5 * h * p0[1];
    const double zh = q0[2] + 0.5 * h * (p0[2] - std::sin(q0[2]));
    const double sh = std::sin(zh), ch = std::cos(zh);
    const double Ux = xh + epsilon * xh * zh * zh, Uy = yh, Uz = zh + epsilon * xh * xh * zh;
    const double p1y = p0[1] - h * Uy;
    const double y1 = yh + 0.5 * h * p1y;
    const double a = 1 - 0.5 * h * ch;
    const double bx = p0[0] - h * Ux;
    const double bz = p0[2] - h * Uz + 0.5 * h * ch * (p0[2] - 2 * sh);
    // Start: g linearized at w = 0 (sin z1 ~ sin z_half + cos z_half (h/2) w),
    // with the sin and cos already at hand.
    double w = (bz - yh * bx - a * sh) / (a * (1 + 0.5 * h * ch) + yh * y1);
    bool converged = false;
    for (int it = 0; it < 20 && !converged; ++it) {
      const double z1 = zh + 0.5 * h * w, s1 = std::sin(z1);
      const double g = (w + s1) * a - bz + yh * (y1 * w + bx);
      const double dg = (1 + 0.5 * h * std::cos(z1)) * a + yh * y1;
      const double dw = g / dg;
      w -= dw;
      ++iterations;
      converged = std::abs(dw) <= 1e-9 * std::abs(w);
    }
    const double z1 = zh + 0.5 * h * w, s1 = std::sin(z1);
    const double p1x = -y1 * w;
    *lambda = (p1x - bx) / h;
    *p1 = Eigen::Vector3d(p1x, p1y, w + s1);
    *q1 = Eigen::Vector3d(xh + 0.5 * h * p1x, y1, z1);
    return converged;
  }
};

}  // namespace floors
