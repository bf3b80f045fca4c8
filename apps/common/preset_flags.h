// Command-line flags under a preset (ctlio_simulate --preset, ctlio_odometry --sim_preset): the
// preset sets the defaults, and a flag the user gave explicitly still wins over it.
#pragma once

#include <gflags/gflags.h>

#include <optional>

namespace ctlio::apps {

// The flag's value when it should apply: always without a preset, with one only if the flag was
// given explicitly on the command line (the preset's value stands otherwise).
template <class T>
std::optional<T> Given(bool have_preset, const char* flag, const T& value) {
  if (!have_preset || !gflags::GetCommandLineFlagInfoOrDie(flag).is_default) return value;
  return std::nullopt;
}

}  // namespace ctlio::apps
