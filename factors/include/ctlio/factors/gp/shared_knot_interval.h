// The work that every GP interpolation between the same two knots repeats — the local variables
// γ_{k+1} = [ξ21; J⁻¹ϖ_{k+1}; …] and their Jacobians (gp::LocalVariables, knot_state.h: the log
// of T_{k+1}T_k⁻¹, J⁻¹, ∂J/∂ξ terms, Ad) — formed once per evaluation point for the interval.
// A scan's ~600 lidar residuals sit at ~600 different firing times and the IMU samples at their
// own times, so the τ-dependent part (Λ(τ), Ω(τ), SPEC §2) is rarely shared; this part depends on
// the two knots only, and is.
//
// KnotValues: a copy of the six knot blocks' values (pose 7, ϖ 6, ϖ̇ 6 of each knot, 38 doubles),
// the key by which anything prepared for "these knot values" is matched to an Evaluate call.
#pragma once

#include <array>
#include <cstring>
#include <optional>

#include "ctlio/factors/gp/knot_state.h"

namespace ctlio::gp {

// The knot blocks in the order pose_k (7), ϖ_k (6), ϖ̇_k (6), pose_k+1, ϖ_k+1, ϖ̇_k+1.
using KnotBlocks = std::array<const double*, 6>;

class KnotValues {
 public:
  static constexpr int kSizes[6] = {7, 6, 6, 7, 6, 6};

  void Read(double const* const* blocks) {
    for (int b = 0, o = 0; b < 6; o += kSizes[b], ++b) {
      std::memcpy(values_.data() + o, blocks[b], kSizes[b] * sizeof(double));
    }
  }
  // Bitwise equality with the blocks' current values.
  bool Equals(double const* const* blocks) const {
    for (int b = 0, o = 0; b < 6; o += kSizes[b], ++b) {
      if (std::memcmp(values_.data() + o, blocks[b], kSizes[b] * sizeof(double)) != 0) {
        return false;
      }
    }
    return true;
  }
  bool operator==(const KnotValues& o) const {
    return std::memcmp(values_.data(), o.values_.data(), sizeof(values_)) == 0;
  }
  // Block b's values (pointers in the KnotBlocks order).
  const double* block(int b) const {
    int o = 0;
    for (int i = 0; i < b; ++i) o += kSizes[i];
    return values_.data() + o;
  }
  KnotState Knot(int which) const {
    return ReadKnotState(block(3 * which), block(3 * which + 1), block(3 * which + 2));
  }

 private:
  std::array<double, 38> values_{};
};

class SharedKnotInterval {
 public:
  explicit SharedKnotInterval(const KnotBlocks& knots) : knots_(knots) {}

  // Reads the knot blocks and forms the local variables (with Jacobians), unless they were
  // formed at exactly these values already. Not concurrently with At().
  void Prepare() {
    if (local_.has_value() && values_.Equals(knots_.data())) return;
    values_.Read(knots_.data());
    local_.emplace(values_.Knot(0), values_.Knot(1), /*with_jacobians=*/true);
    local_->AddChainProducts();
  }
  // The local variables if the last Prepare() saw exactly `values`, otherwise null.
  const LocalVariables* At(const KnotValues& values) const {
    return local_.has_value() && values_ == values ? &*local_ : nullptr;
  }
  const KnotBlocks& knots() const { return knots_; }

 private:
  KnotBlocks knots_;
  KnotValues values_;
  std::optional<LocalVariables> local_;
};

}  // namespace ctlio::gp
