// Ros2BagReader: a bag folder (metadata.yaml and its storage files, read in the listed order), a
// folder of .mcap/.db3 files without metadata.yaml (read in name order, with a warning), or one
// storage file. Topics are merged by name over the files.
#include <glog/logging.h>

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include "ctlio/io/ros2_bag.h"
#include "storage.h"

namespace fs = std::filesystem;

namespace ctlio::io::ros2 {
namespace {

std::unique_ptr<StorageReader> OpenStorage(const std::string& file) {
  if (HasMcapMagic(file)) return OpenMcap(file);
  if (HasSqliteHeader(file)) return OpenSqlite(file);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw std::runtime_error(file + ": no such file");
  throw std::runtime_error(file + ": neither an MCAP nor an SQLite 3 file");
}

}  // namespace

bool IsRos2Bag(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) return fs::is_regular_file(fs::path(path) / "metadata.yaml", ec);
  if (!fs::is_regular_file(path, ec)) return false;
  return HasMcapMagic(path) || (HasSqliteHeader(path) && IsRosbag2Sqlite(path));
}

struct Ros2BagReader::Impl {
  std::string path;
  std::vector<std::string> files;
  std::vector<Ros2Topic> topics;
  std::vector<std::vector<size_t>> to_bag;  // per file: its topic index -> the bag's
  std::vector<bool> wanted;
  size_t current = 0;
  std::unique_ptr<StorageReader> reader;
  uint64_t bytes = 0;
  std::string last_where;  // of the last message, once its file is closed
  std::vector<std::string> recovered;

  void Merge(size_t file, const std::vector<Ros2Topic>& file_topics) {
    for (const Ros2Topic& t : file_topics) {
      size_t i = 0;
      while (i < topics.size() && topics[i].name != t.name) ++i;
      if (i == topics.size()) {
        topics.push_back(t);
        topics.back().message_count = 0;
      } else if (topics[i].type != t.type) {
        throw std::runtime_error(files[file] + ": topic '" + t.name + "' has type '" + t.type +
                                 "', and '" + topics[i].type + "' in " + files[0]);
      }
      topics[i].message_count += t.message_count;
      to_bag[file].push_back(i);
    }
  }
  void Open(size_t file) {
    reader = OpenStorage(files[file]);
    if (reader->topics().size() != to_bag[file].size()) {
      throw std::runtime_error(files[file] + ": changed while being read");
    }
    std::vector<bool> local(to_bag[file].size());
    for (size_t i = 0; i < local.size(); ++i) local[i] = wanted[to_bag[file][i]];
    reader->SetFilter(local);
  }
};

Ros2BagReader::Ros2BagReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  std::error_code ec;
  BagMetadata meta;
  if (fs::is_directory(path, ec)) {
    if (fs::is_regular_file(fs::path(path) / "metadata.yaml", ec)) {
      meta = ReadBagMetadata(path);
      for (const std::string& f : meta.relative_file_paths) {
        const std::string file = (fs::path(path) / f).string();
        if (!fs::is_regular_file(file, ec)) {
          throw std::runtime_error(path + "/metadata.yaml lists " + f + ", but " + file +
                                   " does not exist");
        }
        m.files.push_back(file);
      }
      if (m.files.empty()) throw std::runtime_error(path + "/metadata.yaml lists no file");
    } else {
      for (const auto& e : fs::directory_iterator(path)) {
        const std::string ext = e.path().extension().string();
        if (e.is_regular_file() && (ext == ".mcap" || ext == ".db3")) {
          m.files.push_back(e.path().string());
        }
      }
      if (m.files.empty()) {
        throw std::runtime_error(path +
                                 ": not a ROS 2 bag folder (no metadata.yaml, no .mcap or "
                                 ".db3 file)");
      }
      std::sort(m.files.begin(), m.files.end());
      LOG(WARNING) << path << ": no metadata.yaml; reading its " << m.files.size()
                   << " .mcap/.db3 file(s) in name order";
    }
  } else if (fs::is_regular_file(path, ec)) {
    m.files.push_back(path);
  } else {
    throw std::runtime_error(path + ": no such file or folder");
  }
  m.to_bag.resize(m.files.size());
  for (size_t f = 0; f < m.files.size(); ++f) {
    auto reader = OpenStorage(m.files[f]);
    m.Merge(f, reader->topics());
    if (std::string r = reader->Recovered(); !r.empty()) m.recovered.push_back(std::move(r));
    if (f == 0) m.reader = std::move(reader);
  }
  // The recorder's counts where the storage gives none (SQLite); topics listed only there too.
  for (const Ros2Topic& t : meta.topics) {
    auto it = std::find_if(m.topics.begin(), m.topics.end(),
                           [&](const Ros2Topic& x) { return x.name == t.name; });
    if (it == m.topics.end()) {
      m.topics.push_back(t);
    } else if (it->message_count == 0) {
      it->message_count = t.message_count;
    }
  }
  m.wanted.assign(m.topics.size(), true);
}

Ros2BagReader::~Ros2BagReader() = default;

const std::string& Ros2BagReader::path() const { return impl_->path; }
const std::vector<Ros2Topic>& Ros2BagReader::topics() const { return impl_->topics; }

void Ros2BagReader::SetTopicFilter(const std::vector<size_t>& topics) {
  Impl& m = *impl_;
  m.wanted.assign(m.topics.size(), false);
  for (size_t t : topics) {
    if (t >= m.topics.size()) {
      throw std::out_of_range(m.path + ": topic index " + std::to_string(t) + " of " +
                              std::to_string(m.topics.size()));
    }
    m.wanted[t] = true;
  }
  if (m.reader) {
    std::vector<bool> local(m.to_bag[m.current].size());
    for (size_t i = 0; i < local.size(); ++i) local[i] = m.wanted[m.to_bag[m.current][i]];
    m.reader->SetFilter(local);
  }
}

bool Ros2BagReader::Next(Ros2Message* message) {
  Impl& m = *impl_;
  while (m.current < m.files.size()) {
    if (!m.reader) m.Open(m.current);
    while (m.reader->Next(message)) {
      message->topic = m.to_bag[m.current][message->topic];
      if (!m.wanted[message->topic]) continue;
      m.bytes += message->data.size();
      return true;
    }
    m.last_where = m.reader->Where();
    m.reader.reset();
    ++m.current;
  }
  return false;
}

uint64_t Ros2BagReader::bytes_read() const { return impl_->bytes; }

const std::vector<std::string>& Ros2BagReader::recovered() const { return impl_->recovered; }

std::string Ros2BagReader::Where() const {
  if (impl_->reader) return impl_->reader->Where();
  return impl_->last_where.empty() ? impl_->path : impl_->last_where;
}

}  // namespace ctlio::io::ros2
