// metadata.yaml of a rosbag2 bag folder (`rosbag2_bagfile_information`, as rosbag2's
// yaml serialization writes it; ctlio writes version 5, the fields every reader since Humble
// knows, and reads any version: only relative_file_paths is required).
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "storage.h"

namespace ctlio::io::ros2 {
namespace {

template <typename T>
T Get(const YAML::Node& node, const char* key, T fallback) {
  const YAML::Node v = node[key];
  return v && !v.IsNull() ? v.as<T>() : fallback;
}

std::string Upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::toupper(c); });
  return s;
}

}  // namespace

BagMetadata ReadBagMetadata(const std::string& folder) {
  const std::string file = (std::filesystem::path(folder) / "metadata.yaml").string();
  BagMetadata m;
  try {
    const YAML::Node root = YAML::LoadFile(file);
    const YAML::Node info = root["rosbag2_bagfile_information"];
    if (!info || !info.IsMap()) {
      throw std::runtime_error(file +
                               ": no 'rosbag2_bagfile_information' (not a ROS 2 bag's "
                               "metadata)");
    }
    m.version = Get<int>(info, "version", 0);
    m.storage_identifier = Get<std::string>(info, "storage_identifier", "");
    const std::string compression_format = Get<std::string>(info, "compression_format", "");
    const std::string compression_mode = Get<std::string>(info, "compression_mode", "");
    if (!compression_format.empty() && Upper(compression_mode) != "NONE") {
      throw std::runtime_error(
          file + ": the bag is compressed (compression_format " + compression_format +
          ", compression_mode " + compression_mode +
          "); ctlio reads uncompressed bags and MCAP chunk compression only: write an "
          "uncompressed copy with `ros2 bag convert` (or zstd -d the files and edit "
          "metadata.yaml)");
    }
    const YAML::Node paths = info["relative_file_paths"];
    if (!paths || !paths.IsSequence()) {
      throw std::runtime_error(file + ": no relative_file_paths list");
    }
    for (const YAML::Node& p : paths) m.relative_file_paths.push_back(p.as<std::string>());
    m.message_count = Get<uint64_t>(info, "message_count", 0);
    if (const YAML::Node d = info["duration"]) m.duration_ns = Get<int64_t>(d, "nanoseconds", 0);
    if (const YAML::Node s = info["starting_time"]) {
      m.start_ns = Get<int64_t>(s, "nanoseconds_since_epoch", 0);
    }
    if (const YAML::Node topics = info["topics_with_message_count"]) {
      for (const YAML::Node& t : topics) {
        const YAML::Node meta = t["topic_metadata"];
        if (!meta) throw std::runtime_error(file + ": a topic without topic_metadata");
        Ros2Topic topic;
        topic.name = Get<std::string>(meta, "name", "");
        topic.type = Get<std::string>(meta, "type", "");
        topic.serialization_format = Get<std::string>(meta, "serialization_format", "cdr");
        topic.message_count = Get<uint64_t>(t, "message_count", 0);
        m.topics.push_back(topic);
      }
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file + ": " + e.what());
  }
  return m;
}

void WriteBagMetadata(const std::string& folder, const BagMetadata& m) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "rosbag2_bagfile_information" << YAML::Value
      << YAML::BeginMap;
  out << YAML::Key << "version" << YAML::Value << 5;
  out << YAML::Key << "storage_identifier" << YAML::Value << m.storage_identifier;
  out << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds"
      << YAML::Value << m.duration_ns << YAML::EndMap;
  out << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key
      << "nanoseconds_since_epoch" << YAML::Value << m.start_ns << YAML::EndMap;
  out << YAML::Key << "message_count" << YAML::Value << m.message_count;
  out << YAML::Key << "topics_with_message_count" << YAML::Value << YAML::BeginSeq;
  for (const Ros2Topic& t : m.topics) {
    out << YAML::BeginMap << YAML::Key << "topic_metadata" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << t.name;
    out << YAML::Key << "type" << YAML::Value << t.type;
    out << YAML::Key << "serialization_format" << YAML::Value << t.serialization_format;
    out << YAML::Key << "offered_qos_profiles" << YAML::Value << YAML::DoubleQuoted << "";
    out << YAML::EndMap;
    out << YAML::Key << "message_count" << YAML::Value << t.message_count << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::Key << "compression_format" << YAML::Value << YAML::DoubleQuoted << "";
  out << YAML::Key << "compression_mode" << YAML::Value << YAML::DoubleQuoted << "";
  out << YAML::Key << "relative_file_paths" << YAML::Value << m.relative_file_paths;
  out << YAML::Key << "files" << YAML::Value << YAML::BeginSeq;
  for (const BagFileInfo& f : m.files) {
    out << YAML::BeginMap << YAML::Key << "path" << YAML::Value << f.path;
    out << YAML::Key << "starting_time" << YAML::Value << YAML::BeginMap << YAML::Key
        << "nanoseconds_since_epoch" << YAML::Value << f.start_ns << YAML::EndMap;
    out << YAML::Key << "duration" << YAML::Value << YAML::BeginMap << YAML::Key << "nanoseconds"
        << YAML::Value << (f.end_ns - f.start_ns) << YAML::EndMap;
    out << YAML::Key << "message_count" << YAML::Value << f.message_count << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap << YAML::EndMap;
  const std::string file = (std::filesystem::path(folder) / "metadata.yaml").string();
  std::ofstream f(file);
  f << out.c_str() << "\n";
  if (!f.flush()) throw std::runtime_error(file + ": cannot write");
}

}  // namespace ctlio::io::ros2
