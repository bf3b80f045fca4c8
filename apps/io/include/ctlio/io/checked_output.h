// Output files whose every write is checked: a full disk, a directory in the file's place or a
// read-only folder must stop the program with the path in the message, never leave an empty or
// truncated result behind an exit status of 0.
#pragma once

#include <fstream>
#include <string>

namespace ctlio::io {

// Opens `path` for writing (truncating); throws "<path>: cannot open for writing (<reason>)".
std::ofstream OpenForWriting(const std::string& path,
                             std::ios::openmode mode = std::ios::out | std::ios::trunc);

// Flushes and closes `out`; throws "<path>: write failed (<reason>)" if any write, the flush or
// the close failed (e.g. ENOSPC).
void CloseChecked(std::ofstream& out, const std::string& path);

// Writes `text` to `path` with both checks.
void WriteTextFile(const std::string& path, const std::string& text);

}  // namespace ctlio::io
