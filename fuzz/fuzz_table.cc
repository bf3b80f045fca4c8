// The CSV/whitespace tables behind every text reader, with each field converted both ways.
#include "ctlio/io/text_table.h"
#include "fuzz_common.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  ctlio::fuzz::QuietLogging();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = ctlio::fuzz::ScratchDir("table") / "in.csv";
  ctlio::fuzz::WriteFile(path, std::string(reinterpret_cast<const char*>(data), size));
  for (const bool header : {false, true}) {
    try {
      const auto rows = ctlio::io::ReadTable(path.string(), header);
      for (const auto& row : rows) {
        for (size_t k = 0; k < row.fields.size(); ++k) {
          try {
            ctlio::io::ToDouble(path.string(), row, k);
          } catch (const std::exception&) {
          }
          try {
            ctlio::io::ToInt64(path.string(), row, k);
          } catch (const std::exception&) {
          }
        }
      }
    } catch (const std::exception&) {
    }
  }
  return 0;
}
