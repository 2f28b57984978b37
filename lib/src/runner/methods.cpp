// MethodSpec::label() and scene_keys(), which read each method's own label
// and keys from the method list.
#include <cstdio>

#include "nhi/methods/methods.hpp"

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
  bool known = false;
  for_each_type(Methods{}, [&](auto tag) { known = known || kind == decltype(tag)::type::name; });
  for (const MethodKey& k : known ? method_flags(kind).keys : std::vector<MethodKey>{}) {
    if (k.kind == MethodKey::Kind::kChoice) {
      if (k.text_of(*this) != k.text_of(defaults)) out += std::string(" ") + k.name + "=" + k.text_of(*this);
    } else if (k.number_of(*this) != k.number_of(defaults)) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "=%g", k.number_of(*this));
      out += std::string(" ") + k.name + buf;
    }
  }
  if (composition != defaults.composition) out += " composition=" + composition;
  return out;
}

}  // namespace nhi
