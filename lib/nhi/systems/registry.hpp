// The system registry: every scene the runner, the studies and the typed tests
// know, in one list.  Adding a scene is one header in systems/ (see system.hpp
// for what a scene provides) and one X(...) entry here; the scene parser, the list of
// system names, parameter defaults and validation, default states, the typed
// test lists and every study's list of scenes all derive from `Systems`.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "nhi/roles/typelist.hpp"
#include "nhi/systems/chaotic_oscillator.hpp"
#include "nhi/systems/chaplygin_sphere.hpp"
#include "nhi/systems/contact_oscillator.hpp"
#include "nhi/systems/contact_oscillator_nr.hpp"
#include "nhi/systems/magnetic_particle.hpp"
#include "nhi/systems/particle.hpp"
#include "nhi/systems/robot.hpp"
#include "nhi/systems/rolling_disk.hpp"
#include "nhi/systems/sleigh.hpp"
#include "nhi/systems/suslov.hpp"

namespace nhi {

// The registration: one X(Type) line for each scene, in this order.
// clang-format off
#define NHI_REGISTERED_SYSTEMS(X) \
  X(Particle)                     \
  X(Robot)                        \
  X(ContactOscillator)            \
  X(ContactOscillatorNR)          \
  X(ChaoticOscillator)            \
  X(Sleigh)                       \
  X(RollingDisk)                  \
  X(MagneticParticle)             \
  X(ChaplyginSphere)              \
  X(Suslov)
// clang-format on

#define NHI_COMMA_THEN_(S) , S
using Systems = typename Rest<TypeList<void NHI_REGISTERED_SYSTEMS(NHI_COMMA_THEN_)>>::type;
#undef NHI_COMMA_THEN_

inline std::vector<std::string> registered_system_names() {
  std::vector<std::string> names;
  for_each_type(Systems{}, [&](auto tag) { names.push_back(decltype(tag)::type::name); });
  return names;
}

}  // namespace nhi
