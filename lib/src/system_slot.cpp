// Compiled once per registered system (CMakeLists.txt builds it with
// NHI_SYSTEM_SLOT = 0, 1, ..., NHI_SYSTEM_SLOTS - 1): every stepper of the
// system at that position of `Systems`, explicitly instantiated, and the
// definitions of run.hpp for it.  Code that includes only the steppers' light
// headers (dla.hpp, mp06.hpp, ...) links to these instances instead of
// compiling the step machinery again; one file per system lets the cores
// build them in parallel.
#include <type_traits>
#include <utility>

#include "nhi/discrete_gradient_body.hpp"
#include "nhi/dla_body.hpp"
#include "nhi/instances.hpp"
#include "nhi/methods.hpp"
#include "nhi/mp06_body.hpp"
#include "nhi/reference_body.hpp"
#include "nhi/run.hpp"
#include "nhi/spark_body.hpp"
#include "nhi/systems/registry.hpp"

#ifndef NHI_SYSTEM_SLOT
#error "build with -DNHI_SYSTEM_SLOT=i"
#endif

namespace nhi {

static_assert(Systems::size == NHI_SYSTEM_SLOTS,
              "CMakeLists.txt counts the systems of systems/registry.hpp; the count does not match");

namespace {

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

}  // namespace

template <class S>
RunReport run_spec(const S& sys, const MethodSpec& spec, const Vec<double, S::n>& q0, const Vec<double, S::n>& v0,
                   double h, long steps, const SampleObserver<S::n, S::m>& observe, const EnergyLimit& limit) {
  return with_stepper(sys, spec, [&](auto& st) {
    if (!limit.on()) return integrate(st, q0, v0, h, steps, observe);
    return integrate(st, q0, v0, h, steps, observe, EnergyGuard<S>(sys, q0, v0, limit));
  });
}

template <class S>
MethodTraits method_traits(const S& sys, const MethodSpec& spec) {
  return with_stepper(sys, spec, [](auto& st) { return st.traits(); });
}

template <class S>
std::unique_ptr<AnyStepper<S::n, S::m>> make_stepper(const S& sys, const MethodSpec& spec) {
  return with_stepper(sys, spec, [](auto& st) -> std::unique_ptr<AnyStepper<S::n, S::m>> {
    using St = std::decay_t<decltype(st)>;
    return std::make_unique<Holder<St>>(std::move(st));
  });
}

#if NHI_SYSTEM_SLOT < NHI_SYSTEM_SLOTS
using SlotSystem = typename At<Systems, NHI_SYSTEM_SLOT>::type;
}  // namespace nhi
NHI_STEPPER_INSTANCES(, nhi::SlotSystem)
namespace nhi {
template RunReport run_spec<SlotSystem>(const SlotSystem&, const MethodSpec&, const Vec<double, SlotSystem::n>&,
                                        const Vec<double, SlotSystem::n>&, double, long,
                                        const SampleObserver<SlotSystem::n, SlotSystem::m>&, const EnergyLimit&);
template MethodTraits method_traits<SlotSystem>(const SlotSystem&, const MethodSpec&);
template std::unique_ptr<AnyStepper<SlotSystem::n, SlotSystem::m>> make_stepper<SlotSystem>(const SlotSystem&,
                                                                                            const MethodSpec&);
#endif

}  // namespace nhi
