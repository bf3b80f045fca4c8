// The CDR decoders of ROS 2 bag messages (cdr_messages.h, cdr_livox.h) on arbitrary bytes: the
// first byte picks the type (PointCloud2, Imu, TFMessage, Odometry, PoseStamped, Livox CustomMsg:
// its value mod 6), the rest is the
// serialized message (encapsulation header and body). Seeds: the simulator's messages as
// WriteRos2Bag encodes them (fuzz_make_seeds). A decoder may throw std::runtime_error; anything
// else is a finding, and so is a decoded message whose encoding does not decode back to the same
// encoding (the decoder and encoder disagree on the layout).
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "ctlio/io/cdr_livox.h"
#include "ctlio/io/cdr_messages.h"
#include "fuzz_common.h"

namespace {

using namespace ctlio::io::ros2;

template <class M>
void RoundTrip(const uint8_t* data, size_t size) {
  M msg;
  try {
    DecodeCdr(data, size, "fuzz: ", &msg);
  } catch (const std::runtime_error&) {
    return;  // a clear error
  }
  const CdrEndian endian = data[1] == 1 ? CdrEndian::kLittle : CdrEndian::kBig;
  // (Compared as bytes: a NaN field is not equal to itself.)
  const std::vector<uint8_t> once = EncodeCdr(msg, endian);
  M again;
  DecodeCdr(once.data(), once.size(), "fuzz (re-encoded): ", &again);
  if (EncodeCdr(again, endian) != once) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (ctlio::fuzz::QuietLogging(), true);
  (void)quiet;
  if (size < 1) return 0;
  const uint8_t* body = data + 1;
  const size_t n = size - 1;
  switch (data[0] % 6) {
    case 0:
      RoundTrip<sensor_msgs::PointCloud2>(body, n);
      break;
    case 1:
      RoundTrip<sensor_msgs::Imu>(body, n);
      break;
    case 2:
      RoundTrip<tf2_msgs::TFMessage>(body, n);
      break;
    case 3:
      RoundTrip<nav_msgs::Odometry>(body, n);
      break;
    case 4:
      RoundTrip<geometry_msgs::PoseStamped>(body, n);
      break;
    default:
      RoundTrip<ctlio::io::livox::CustomMsg>(body, n);
      break;
  }
  return 0;
}
