// MethodSpec::label() and scene_keys(), which read each method's own label
// and keys from the method list.
#include <cstdio>

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
  bool known = false;
  for_each_type(Methods{}, [&](auto tag) { known = known || kind == decltype(tag)::type::name; });
  for (const MethodKey& k : known ? method_flags(kind).keys : std::vector<MethodKey>{}) {
    if (k.text && this->*k.text != defaults.*k.text) out += std::string(" ") + k.name + "=" + this->*k.text;
    if (k.whole && this->*k.whole != defaults.*k.whole)
      out += std::string(" ") + k.name + "=" + std::to_string(this->*k.whole);
    if (k.number && this->*k.number != defaults.*k.number) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "=%g", this->*k.number);
      out += std::string(" ") + k.name + buf;
    }
  }
  if (composition != defaults.composition) out += " composition=" + composition;
  return out;
}

}  // namespace nhi
