// What the SlidingWindow's source files share (sliding_window.cc: states and residual blocks,
// solve, marginalisation, covariance; sliding_window_linearize.cc: the linearisation).
#pragma once

#include <Eigen/Core>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ctlio/solvers/sliding_window.h"

namespace ctlio::sliding_window_internal {

// "<file>:<line>: SlidingWindow: <what>", the file and line of the call.
template <typename Exception = std::invalid_argument>
[[noreturn]] void Throw(int line, const std::string& what, const char* file = __builtin_FILE()) {
  std::ostringstream msg;
  msg << file << ":" << line << ": SlidingWindow: " << what;
  throw Exception(msg.str());
}

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

inline std::string IdList(const std::vector<StateId>& ids) {
  std::ostringstream s;
  for (size_t i = 0; i < ids.size(); ++i) s << (i ? ", " : "") << ids[i];
  return s.str();
}

}  // namespace ctlio::sliding_window_internal
