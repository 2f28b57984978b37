// The definitions of MethodRun (run.hpp): one method's stepper behind the
// runner's dispatch.  Each method's translation unit (lib/src/methods/*.cpp)
// includes this header and instantiates MethodRun<M, S> for every registered
// system S (NHI_REGISTERED_SYSTEMS), e.g.
//   #define NHI_INSTANCES_(S) template struct nhi::MethodRun<nhi::Rk4Method, nhi::S>;
//   NHI_REGISTERED_SYSTEMS(NHI_INSTANCES_)
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

#include "nhi/roles/guard.hpp"
#include "nhi/roles/integrate.hpp"
#include "nhi/runner/run.hpp"
#include "nhi/systems/registry.hpp"

namespace nhi {
namespace detail {

template <class St>
class Holder final : public AnyStepper<St::n, St::m> {
 public:
  explicit Holder(St&& st) : st_(std::move(st)) {}
  MethodTraits traits() const override { return st_.traits(); }
  int lag() const override { return St::lag; }
  void start(const Vec<double, St::n>& q0, const Vec<double, St::n>& v0) override { st_.start(q0, v0); }
  StepSummary step(double h) override { return st_.step(h); }
  void sample(Sample<St::n, St::m>* s) const override { st_.sample(s); }
  Vec<double, 2 * St::n> phase() const override { return st_.phase(); }

 private:
  St st_;
};

}  // namespace detail

template <class M, class S>
RunReport MethodRun<M, S>::run(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0,
                               const Vec<double, S::n>& v0, double h, long steps,
                               const SampleObserver<S::n, S::m>& observe, const EnergyLimit& limit) {
  return M::with_stepper(sys, spec, [&](auto& st) {
    if (!limit.on()) return integrate(st, q0, v0, h, steps, observe);
    return integrate(st, q0, v0, h, steps, observe, EnergyGuard<S>(sys, q0, v0, limit));
  });
}

template <class M, class S>
MethodTraits MethodRun<M, S>::traits(const S& sys, const MethodSpec& spec) {
  return M::with_stepper(sys, spec, [](auto& st) { return st.traits(); });
}

template <class M, class S>
std::unique_ptr<AnyStepper<S::n, S::m>> MethodRun<M, S>::make(const S& sys, const MethodSpec& spec) {
  return M::with_stepper(sys, spec, [](auto& st) -> std::unique_ptr<AnyStepper<S::n, S::m>> {
    using St = std::decay_t<decltype(st)>;
    return std::make_unique<detail::Holder<St>>(std::move(st));
  });
}

}  // namespace nhi
