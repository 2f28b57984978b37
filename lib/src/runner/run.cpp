// The runner's dispatch (run.hpp): run_spec(), method_traits() and
// make_stepper() find the method the spec names in methods.hpp's Methods and
// call its MethodRun, compiled in the method's own translation unit
// (lib/src/methods/*.cpp).  Defined here for every registered system.
#include <optional>
#include <stdexcept>
#include <utility>

#include "nhi/methods/methods.hpp"
#include "nhi/runner/run.hpp"
#include "nhi/systems/registry.hpp"

namespace nhi {
namespace {

// f(Tag<MethodRun<M, S>>{}) for the method M the spec names; an unknown name is
// an error, never a fallback.
template <class S, class F>
auto with_method_run(const MethodSpec& spec, F&& f) {
  using R = decltype(f(Tag<MethodRun<Rk4Method, S>>{}));
  std::optional<R> out;
  for_each_type(Methods{}, [&](auto tag) {
    using M = typename decltype(tag)::type;
    if (!out && spec.kind == M::name) out.emplace(f(Tag<MethodRun<M, S>>{}));
  });
  if (!out) throw std::invalid_argument("unknown method \"" + spec.kind + "\"");
  return std::move(*out);
}

}  // namespace

template <class S>
RunReport run_spec(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                   double h, long steps, const SampleObserver<S::n, S::m>& observe, const EnergyLimit& limit) {
  return with_method_run<S>(
      spec, [&](auto run) { return decltype(run)::type::run(sys, spec, q0, v0, h, steps, observe, limit); });
}

template <class S>
MethodTraits method_traits(const S& sys, const MethodSpec& spec) {
  return with_method_run<S>(spec, [&](auto run) { return decltype(run)::type::traits(sys, spec); });
}

template <class S>
std::unique_ptr<AnyStepper<S::n, S::m>> make_stepper(const S& sys, const MethodSpec& spec) {
  return with_method_run<S>(spec, [&](auto run) { return decltype(run)::type::make(sys, spec); });
}

}  // namespace nhi

#define NHI_RUN_INSTANCES_(S)                                                                                        \
  template nhi::RunReport nhi::run_spec<nhi::S>(                                                                     \
      const nhi::S&, const nhi::MethodSpec&, const nhi::Vec<double, nhi::S::n>&, const nhi::Vec<double, nhi::S::n>&, \
      double, long, const nhi::SampleObserver<nhi::S::n, nhi::S::m>&, const nhi::EnergyLimit&);                      \
  template nhi::MethodTraits nhi::method_traits<nhi::S>(const nhi::S&, const nhi::MethodSpec&);                      \
  template std::unique_ptr<nhi::AnyStepper<nhi::S::n, nhi::S::m>> nhi::make_stepper<nhi::S>(const nhi::S&,           \
                                                                                            const nhi::MethodSpec&);
NHI_REGISTERED_SYSTEMS(NHI_RUN_INSTANCES_)
