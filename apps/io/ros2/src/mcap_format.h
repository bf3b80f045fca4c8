// MCAP's constants (https://mcap.dev/spec) shared by ctlio's reader and writer.
#pragma once

#include <cstdint>

namespace ctlio::io::ros2::mcap {

// 0x89 "MCAP" major version '0' "\r\n": at the start and the end of every file.
constexpr uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr uint64_t kRecordPrefix = 1 + 8;  // opcode, content length
// The footer record (summary_start, summary_offset_start, summary_crc) before the end magic.
constexpr uint64_t kFooterContent = 8 + 8 + 4;
constexpr uint64_t kFooterRecord = kRecordPrefix + kFooterContent;

enum Op : uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

}  // namespace ctlio::io::ros2::mcap
