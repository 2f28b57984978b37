// Scene: the Chaplygin sleigh, and with a = 0 and g != 0 the knife edge on an
// inclined plane (Bloch, "Nonholonomic Mechanics and Control", secs. 1.7, 1.6).
//   Q = SE(2), q = (x, y, theta), (x, y) the centre of mass, theta the heading
//   (a real coordinate: the identity chart on its lift, paper Remark 4.1).
//   L = 1/2 m (xd^2 + yd^2) + 1/2 I thetad^2 - m g y
//   constraint  -sin(theta) xd + cos(theta) yd - a thetad = 0:
//   the blade, a distance a behind the centre of mass, does not slip sideways.
// In the body frame, u = cos(theta) xd + sin(theta) yd is the forward speed
// and the lateral speed is a w, w = thetad.
//
// Index-reduced ODE (M = diag(m, m, I), f = (0, -m g, 0)):
//   d/dt (omega v) = omega a - w u = 0  gives
//   lambda = (g cos(theta) + w u) / (1/m + a^2/I),
//   a = (-sin(theta) lambda / m, -g + cos(theta) lambda / m, -a lambda / I).
//
// Exact solutions (exact_solution() below):
//  * g = 0 (the sleigh).  u' = a w^2, w' = -m a u w / (I + m a^2), and the energy
//    E = 1/2 m u^2 + 1/2 (I + m a^2) w^2 is constant, so with c = sqrt(2E/m),
//    k = m a c / (I + m a^2):
//      u(t) = c tanh(k (t - t*)),   w(t) = w* sech(k (t - t*)),
//      theta(t) = theta0 + (w*/k) (gd(k (t - t*)) - gd(-k t*)),  gd(s) = atan(sinh s),
//    with t* = -atanh(u0/c)/k, w* = w0 cosh(k t*).  x and y are the integrals of
//    xd = u cos(theta) - a w sin(theta), yd = u sin(theta) + a w cos(theta),
//    which have no elementary form: Gauss-Kronrod quadrature (Boost.Math) of the
//    closed-form integrand, to 1e-13 relative (at most 2^12 subintervals).  The motion tends to a straight
//    line at speed c (w -> 0): reversible, but not integrable in the KAM sense.
//  * a = 0 (the knife edge).  w = w0, theta = theta0 + w0 t, u' = -g sin(theta),
//    so u = A + B cos(theta) with B = g/w0, A = u0 - B cos(theta0), and
//      x = x0 + (A/w0)(sin th - sin th0) + B t/2 + (B/4w0)(sin 2th - sin 2th0),
//      y = y0 - (A/w0)(cos th - cos th0) - (B/4w0)(cos 2th - cos 2th0)
//    (w0 = 0: u = u0 - g sin(th0) t along a fixed line).
//  With a != 0 and g != 0 there is none (exact_solution returns false).
//
// Default run (experiments/scenes/sleigh.json): m = I = a = 1, g = 0,
// q0 = (0, 0, 0), v0 = (-1, 1, 1): the sleigh starts backwards (u0 = -1) while
// turning (w0 = 1); E = 1.5, c = sqrt(3), k = sqrt(3)/2, and at t* = 0.760 the
// forward speed changes sign and the turn rate peaks (w* = 1.225) before both
// settle to straight-line motion at speed sqrt(3).
#pragma once

#include <algorithm>
#include <array>
#include <boost/math/quadrature/gauss_kronrod.hpp>
#include <cmath>

#include "nhi/roles/system.hpp"

namespace nhi {

struct Sleigh {
  static constexpr int n = 3;
  static constexpr int m = 1;
  static constexpr const char* name = "sleigh";
  // L and omega are invariant under (q, v) -> (q, -v); not integrable (see above).
  static constexpr bool reversible = true;
  // With g = 0 every motion tends to a straight line (w -> 0, see above).
  static constexpr const char* behaviour = "attracted to a line";
  static constexpr bool separable = true;  // M constant, U = m g y

  double mass = 1.0;
  double I = 1.0;
  double a = 1.0;
  double g = 0.0;

  static auto parameters() {
    using P = Param<Sleigh>;
    return std::array{P{"m", &Sleigh::mass, ParamCheck::kPositive}, P{"I", &Sleigh::I, ParamCheck::kPositive},
                      P{"a", &Sleigh::a, ParamCheck::kNonNegative}, P{"g", &Sleigh::g}};
  }
  static Vec<double, 3> default_q0() { return {0.0, 0.0, 0.0}; }
  static Vec<double, 3> default_v0() { return {-1.0, 1.0, 1.0}; }

  template <class T>
  T lagrangian(const Vec<T, 3>& q, const Vec<T, 3>& v) const {
    return cst<T>(0.5 * mass) * (v[0] * v[0] + v[1] * v[1]) + cst<T>(0.5 * I) * v[2] * v[2] - cst<T>(mass * g) * q[1];
  }

  template <class T>
  void partials(const Vec<T, 3>&, const Vec<T, 3>& v, Vec<T, 3>* dLdq, Vec<T, 3>* dLdv) const {
    *dLdq << cst<T>(0.0), cst<T>(-mass * g), cst<T>(0.0);
    *dLdv << cst<T>(mass) * v[0], cst<T>(mass) * v[1], cst<T>(I) * v[2];
  }

  template <class T>
  Vec<T, 3> velocity(const Vec<T, 3>&, const Vec<T, 3>& p) const {
    Vec<T, 3> v;
    v << p[0] / cst<T>(mass), p[1] / cst<T>(mass), p[2] / cst<T>(I);
    return v;
  }

  template <class T>
  Mat<T, 1, 3> omega(const Vec<T, 3>& q) const {
    using std::cos;
    using std::sin;
    const T s = sin(q[2]), c = cos(q[2]);  // one sincos call (robot.hpp)
    Mat<T, 1, 3> w;
    w << -s, c, cst<T>(-a);
    return w;
  }

  Vec<double, 3> acceleration(const Vec<double, 3>& q, const Vec<double, 3>& v) const {
    const double c = std::cos(q[2]), s = std::sin(q[2]);
    const double u = c * v[0] + s * v[1];
    const double lambda = (g * c + v[2] * u) / (1.0 / mass + a * a / I);
    return {-s * lambda / mass, -g + c * lambda / mass, -a * lambda / I};
  }

  // The exact solution at time t from (q0, v0) (see the top of this file), for
  // g = 0 or a = 0; false (and nothing written) otherwise.
  bool exact_solution(const Vec<double, 3>& q0, const Vec<double, 3>& v0, double t, Vec<double, 3>* q,
                      Vec<double, 3>* v) const {
    const double th0 = q0[2], w0 = v0[2];
    const double u0 = std::cos(th0) * v0[0] + std::sin(th0) * v0[1];
    if (a == 0.0) {  // the knife edge
      double x, y, u;
      const double th = th0 + w0 * t;
      if (w0 == 0.0) {
        u = u0 - g * std::sin(th0) * t;
        const double s = u0 * t - 0.5 * g * std::sin(th0) * t * t;
        x = q0[0] + std::cos(th0) * s;
        y = q0[1] + std::sin(th0) * s;
      } else {
        const double B = g / w0, A = u0 - B * std::cos(th0);
        u = A + B * std::cos(th);
        x = q0[0] + A / w0 * (std::sin(th) - std::sin(th0)) + 0.5 * B * t +
            B / (4 * w0) * (std::sin(2 * th) - std::sin(2 * th0));
        y = q0[1] - A / w0 * (std::cos(th) - std::cos(th0)) - B / (4 * w0) * (std::cos(2 * th) - std::cos(2 * th0));
      }
      *q << x, y, th;
      *v << u * std::cos(th), u * std::sin(th), w0;
      return true;
    }
    if (g != 0.0) return false;
    // The sleigh: body velocities and heading in closed form, position by quadrature.
    auto body = [&](double s, double* u, double* w, double* th) {
      if (w0 == 0.0) {
        *u = u0;
        *w = 0.0;
        *th = th0;
        return;
      }
      const double E = 0.5 * mass * u0 * u0 + 0.5 * (I + mass * a * a) * w0 * w0;
      const double c = std::sqrt(2 * E / mass), k = mass * a * c / (I + mass * a * a);
      const double ts = -std::atanh(u0 / c) / k, ws = w0 * std::cosh(k * ts);
      *u = c * std::tanh(k * (s - ts));
      *w = ws / std::cosh(k * (s - ts));
      *th = th0 + ws / k * (std::atan(std::sinh(k * (s - ts))) - std::atan(std::sinh(-k * ts)));
    };
    auto inertial = [&](double s) {
      double u, w, th;
      body(s, &u, &w, &th);
      return Vec<double, 3>(u * std::cos(th) - a * w * std::sin(th), u * std::sin(th) + a * w * std::cos(th), w);
    };
    using GK = boost::math::quadrature::gauss_kronrod<double, 61>;
    const double x = GK::integrate([&](double s) { return inertial(s)[0]; }, 0.0, t, 12, 1e-13);
    const double y = GK::integrate([&](double s) { return inertial(s)[1]; }, 0.0, t, 12, 1e-13);
    double u, w, th;
    body(t, &u, &w, &th);
    *q << q0[0] + x, q0[1] + y, th;
    *v = inertial(t);
    return true;
  }

  // The forward speed u = cos(theta) xd + sin(theta) yd (the body frame's).
  static double forward_speed(const Vec<double, 3>& q, const Vec<double, 3>& v) {
    return std::cos(q[2]) * v[0] + std::sin(q[2]) * v[1];
  }

  // The motion's limit as t -> infinity (g = 0, a > 0; false otherwise): the
  // forward speed c = sqrt(2E/m) (u = c tanh(k (t - t*)) -> c) and the heading
  //   theta_inf = theta0 + (w*/k) (pi/2 - gd(-k t*)),  gd(s) = atan(sinh s)
  // (the closed form above with gd(+inf) = pi/2).  With w0 = 0 the sleigh
  // keeps u0 and theta0.  *settle (may be null): a time after which the turn
  // rate w* sech(k (t - t*)) is below 2 e^-30 ~ 2e-13 of its peak, t* + 30 / k.
  bool limit_motion(const Vec<double, 3>& q0, const Vec<double, 3>& v0, double* speed, double* heading,
                    double* settle = nullptr) const {
    if (g != 0.0 || a == 0.0) return false;
    const double th0 = q0[2], w0 = v0[2];
    const double u0 = std::cos(th0) * v0[0] + std::sin(th0) * v0[1];
    if (w0 == 0.0) {
      *speed = u0;
      *heading = th0;
      if (settle) *settle = 0.0;
      return true;
    }
    const double E = 0.5 * mass * u0 * u0 + 0.5 * (I + mass * a * a) * w0 * w0;
    const double c = std::sqrt(2 * E / mass), k = mass * a * c / (I + mass * a * a);
    const double ts = -std::atanh(u0 / c) / k, ws = w0 * std::cosh(k * ts);
    if (settle) *settle = std::max(0.0, ts) + 30.0 / k;
    *speed = c;
    *heading = th0 + ws / k * (0.5 * M_PI - std::atan(std::sinh(-k * ts)));
    return true;
  }
};

}  // namespace nhi
