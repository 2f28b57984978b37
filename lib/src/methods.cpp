// MethodSpec::label(), which reads each method's own label from the method list.
#include "nhi/methods.hpp"

namespace nhi {

std::string MethodSpec::label() const {
  std::string base = kind;
  for_each_type(Methods{}, [&](auto tag) {
    using M = typename decltype(tag)::type;
    if (kind == M::name) base = M::label(*this);
  });
  return composition == "none" ? base : base + "+" + composition;
}

std::string MethodSpec::scene_keys() const {
  const MethodSpec defaults;
  std::string out = "method=" + kind;
  bool discretized = false;
  for_each_type(Methods{}, [&](auto tag) {
    if (kind == decltype(tag)::type::name) discretized = decltype(tag)::type::uses_discretization;
  });
  if (discretized && discretization != defaults.discretization) out += " discretization=" + discretization;
  if (discretized && alpha != defaults.alpha) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " alpha=%g", alpha);
    out += buf;
  }
  if (kind == SparkMethod::name && stages != defaults.stages) out += " stages=" + std::to_string(stages);
  if (kind == DiscreteGradientMethod::name && constraint != defaults.constraint) out += " constraint=" + constraint;
  if (composition != defaults.composition) out += " composition=" + composition;
  return out;
}

}  // namespace nhi
