// Ros2BagWriter: a bag folder <name>/ with <name>_0.mcap or <name>_0.db3 and metadata.yaml, as
// `ros2 bag record` writes one (a single file: ctlio does not split).
#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "ctlio/io/ros2_bag.h"
#include "storage.h"

namespace fs = std::filesystem;

namespace ctlio::io::ros2 {

struct Ros2BagWriter::Impl {
  std::string path;
  BagMetadata meta;
  std::unique_ptr<StorageWriter> storage;
  bool closed = false;
};

Ros2BagWriter::Ros2BagWriter(const std::string& path, Ros2Storage storage,
                             Ros2Compression compression)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  std::error_code ec;
  if (fs::exists(path, ec) && (!fs::is_directory(path, ec) || !fs::is_empty(path, ec))) {
    throw std::runtime_error(path +
                             ": exists and is not an empty folder (a ROS 2 bag is written "
                             "into a new folder)");
  }
  fs::create_directories(path, ec);
  if (ec) throw std::runtime_error(path + ": cannot create the folder: " + ec.message());
  std::string name = fs::path(path).filename().string();
  if (name.empty()) name = fs::path(path).parent_path().filename().string();
  if (storage == Ros2Storage::kMcap) {
    McapWriteOptions o;
    o.compression = compression == Ros2Compression::kZstd  ? "zstd"
                    : compression == Ros2Compression::kLz4 ? "lz4"
                                                           : "";
    m.meta.storage_identifier = "mcap";
    m.meta.relative_file_paths = {name + "_0.mcap"};
    m.storage = CreateMcap((fs::path(path) / m.meta.relative_file_paths[0]).string(), o);
  } else {
    if (compression != Ros2Compression::kNone) {
      throw std::runtime_error(path +
                               ": compression applies to MCAP chunks; SQLite bags are "
                               "written uncompressed");
    }
    m.meta.storage_identifier = "sqlite3";
    m.meta.relative_file_paths = {name + "_0.db3"};
    m.storage = CreateSqlite((fs::path(path) / m.meta.relative_file_paths[0]).string());
  }
  m.meta.files.push_back({m.meta.relative_file_paths[0], 0, 0, 0});
}

Ros2BagWriter::~Ros2BagWriter() {
  if (impl_->closed) return;
  try {
    Close();
  } catch (const std::exception& e) {
    LOG(ERROR) << e.what();
  }
}

size_t Ros2BagWriter::AddTopic(const std::string& name, const std::string& type) {
  Impl& m = *impl_;
  if (m.closed) throw std::logic_error(m.path + ": AddTopic after Close");
  for (size_t i = 0; i < m.meta.topics.size(); ++i) {
    if (m.meta.topics[i].name != name) continue;
    if (m.meta.topics[i].type != type) {
      throw std::runtime_error(m.path + ": topic '" + name + "' added with types '" +
                               m.meta.topics[i].type + "' and '" + type + "'");
    }
    return i;
  }
  m.storage->AddTopic(m.meta.topics.size(), name, type);
  m.meta.topics.push_back({name, type, "cdr", 0});
  return m.meta.topics.size() - 1;
}

void Ros2BagWriter::Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) {
  Impl& m = *impl_;
  if (m.closed) throw std::logic_error(m.path + ": Write after Close");
  if (topic >= m.meta.topics.size()) {
    throw std::out_of_range(m.path + ": topic index " + std::to_string(topic) + " of " +
                            std::to_string(m.meta.topics.size()));
  }
  m.storage->Write(topic, log_time_ns, data);
  BagFileInfo& f = m.meta.files[0];
  f.start_ns = f.message_count == 0 ? log_time_ns : std::min(f.start_ns, log_time_ns);
  f.end_ns = f.message_count == 0 ? log_time_ns : std::max(f.end_ns, log_time_ns);
  ++f.message_count;
  ++m.meta.topics[topic].message_count;
}

void Ros2BagWriter::Close() {
  Impl& m = *impl_;
  if (m.closed) return;
  m.closed = true;
  m.storage->Close();
  const BagFileInfo& f = m.meta.files[0];
  m.meta.start_ns = f.start_ns;
  m.meta.duration_ns = f.end_ns - f.start_ns;
  m.meta.message_count = f.message_count;
  WriteBagMetadata(m.path, m.meta);
}

}  // namespace ctlio::io::ros2
