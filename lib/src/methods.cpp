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

}  // namespace nhi
