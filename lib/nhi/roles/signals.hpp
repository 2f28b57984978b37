// One signal handler for every executable: SIGINT and SIGTERM set
// interrupt_flag() (stepper.hpp), every integrate loop stops at its next step,
// and the program then exits 130 having written nothing.
#pragma once

#include <csignal>

#include "nhi/roles/stepper.hpp"

namespace nhi {

namespace detail {
inline void on_interrupt(int) { interrupt_flag().store(true); }
}  // namespace detail

inline void install_interrupt_handlers() {
  std::signal(SIGINT, detail::on_interrupt);
  std::signal(SIGTERM, detail::on_interrupt);
}

}  // namespace nhi
