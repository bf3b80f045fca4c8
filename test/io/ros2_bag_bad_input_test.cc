// ROS 2 bag containers on bad input: truncated and corrupted MCAP files, wrong magic, a missing
// file, compressed bags, SQLite files that are not rosbag2's. Every error is a std::runtime_error
// naming the file (and for MCAP the byte offset); nothing crashes or allocates from a corrupt
// length.
#include <sqlite3.h>

#include <cstring>

#include "ros2_bag_fixture.h"

namespace ctlio::io::ros2::testing {
namespace {

// Offset of the first record with `opcode` after the magic and header (test bags only: walks
// the top-level records).
size_t FindRecord(const std::string& bytes, uint8_t opcode) {
  size_t off = 8;
  while (off + 9 <= bytes.size()) {
    uint64_t len = 0;
    std::memcpy(&len, bytes.data() + off + 1, 8);
    if (static_cast<uint8_t>(bytes[off]) == opcode) return off;
    off += 9 + len;
  }
  return std::string::npos;
}

void PutU64(std::string* bytes, size_t at, uint64_t v) { std::memcpy(&(*bytes)[at], &v, 8); }

TEST_F(Ros2BagTest, TruncatedMcapIsAnErrorNamingTheFileAtEveryCut) {
  for (const bool summary : {true, false}) {
    McapWriteOptions o;
    o.compression = "zstd";
    o.chunk_bytes = 3000;
    o.summary = summary;
    const std::string good = Bytes(WriteMcap("good.mcap", o, Messages(10, 5)));
    const std::string cut = (dir_ / "cut.mcap").string();
    // Every cut in the header, the first records and the summary/footer; every 11th elsewhere.
    for (size_t n = 0; n < good.size(); n += (n < 512 || n + 1024 > good.size()) ? 1 : 11) {
      Put(cut, good.substr(0, n));
      const std::string error = ReadError(cut);
      ASSERT_NE(error.find(cut), std::string::npos) << "cut at " << n << ": '" << error << "'";
    }
  }
}

TEST_F(Ros2BagTest, CorruptLengthsAreErrorsWithTheirByteOffset) {
  for (const bool summary : {true, false}) {
    McapWriteOptions o;
    o.chunk_bytes = 3000;
    o.summary = summary;
    const std::string good = Bytes(WriteMcap("good.mcap", o, Messages(10, 5)));
    const size_t chunk = FindRecord(good, 0x06);
    ASSERT_NE(chunk, std::string::npos);
    const std::string bad = (dir_ / "bad.mcap").string();
    // The chunk record's length, then its uncompressed size and its records' length: 2^63.
    for (const size_t field : {chunk + 1, chunk + 9 + 16, chunk + 9 + 32}) {
      std::string bytes = good;
      PutU64(&bytes, field, uint64_t{1} << 63);
      Put(bad, bytes);
      const std::string error = ReadError(bad);
      EXPECT_NE(error.find(bad + ": "), std::string::npos) << error;
      EXPECT_NE(error.find("byte"), std::string::npos) << error;
    }
    // A message's length inside the chunk (uncompressed: at a known place): 2^40.
    std::string bytes = good;
    PutU64(&bytes, chunk + 9 + 40 + 1, uint64_t{1} << 40);
    Put(bad, bytes);
    EXPECT_NE(ReadError(bad).find(bad), std::string::npos);
  }
}

TEST_F(Ros2BagTest, CorruptChunkDataFailsItsCrc) {
  McapWriteOptions o;
  const std::string good = Bytes(WriteMcap("good.mcap", o, Messages(10, 5)));
  std::string bytes = good;
  bytes[FindRecord(good, 0x06) + 200] ^= 0x40;
  const std::string bad = (dir_ / "bad.mcap").string();
  Put(bad, bytes);
  EXPECT_NE(ReadError(bad).find("CRC"), std::string::npos) << ReadError(bad);
}

TEST_F(Ros2BagTest, OversizedChunkIsRefusedBeforeDecompressing) {
  McapWriteOptions o;
  o.compression = "lz4";
  const std::string good = Bytes(WriteMcap("good.mcap", o, Messages(10, 5)));
  std::string bytes = good;
  PutU64(&bytes, FindRecord(good, 0x06) + 9 + 16, uint64_t{1} << 31);  // uncompressed_size
  const std::string bad = (dir_ / "bad.mcap").string();
  Put(bad, bytes);
  EXPECT_NE(ReadError(bad).find("beyond ctlio's limit"), std::string::npos) << ReadError(bad);
}

TEST_F(Ros2BagTest, WrongMagicOrFormatIsNamed) {
  const std::string good = Bytes(WriteMcap("good.mcap", McapWriteOptions(), Messages(10, 5)));
  const std::string bad = (dir_ / "bad.mcap").string();
  std::string bytes = good;
  bytes[3] = 'X';
  Put(bad, bytes);
  EXPECT_FALSE(IsRos2Bag(bad));
  EXPECT_NE(ReadError(bad).find("neither an MCAP nor an SQLite"), std::string::npos);
  bytes = good;
  bytes[bytes.size() - 2] = 'X';  // the end magic
  Put(bad, bytes);
  EXPECT_TRUE(IsRos2Bag(bad));
  EXPECT_NE(ReadError(bad).find("does not end with the MCAP magic"), std::string::npos);
  EXPECT_NE(ReadError((dir_ / "none.mcap").string()).find("no such file"), std::string::npos);
}

TEST_F(Ros2BagTest, MissingOrCompressedFileOfMetadataIsNamed) {
  const std::string bag = Write("bag", Ros2Storage::kMcap, Ros2Compression::kNone, Messages(5, 1));
  std::string yaml = Bytes(bag + "/metadata.yaml");
  Put(bag + "/metadata.yaml", yaml + "");
  fs::rename(bag + "/bag_0.mcap", bag + "/moved.mcap");
  std::string error = ReadError(bag);
  EXPECT_NE(error.find("lists bag_0.mcap"), std::string::npos) << error;
  fs::rename(bag + "/moved.mcap", bag + "/bag_0.mcap");
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"compression_format: \"\"", "compression_format: zstd"},
        {"compression_mode: \"\"", "compression_mode: FILE"}}) {
    const size_t at = yaml.find(from);
    ASSERT_NE(at, std::string::npos) << yaml;
    yaml.replace(at, from.size(), to);
  }
  Put(bag + "/metadata.yaml", yaml);
  error = ReadError(bag);
  EXPECT_NE(error.find("compression_mode FILE"), std::string::npos) << error;
  EXPECT_NE(error.find("metadata.yaml"), std::string::npos) << error;
  Put(bag + "/metadata.yaml", "rosbag2_bagfile_information: [1, 2\n");
  EXPECT_NE(ReadError(bag).find("metadata.yaml"), std::string::npos) << ReadError(bag);
}

TEST_F(Ros2BagTest, SqliteWithoutRosbag2TablesIsNamed) {
  const std::string db = (dir_ / "other.db3").string();
  sqlite3* h = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(h,
                         "CREATE TABLE topics(id INTEGER, name TEXT); INSERT INTO topics "
                         "VALUES (1, 'a');",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(h);
  EXPECT_FALSE(IsRos2Bag(db));
  const std::string error = ReadError(db);
  EXPECT_NE(error.find(db + ": an SQLite file but not a rosbag2 bag"), std::string::npos) << error;
  // A message naming a topic id the topics table lacks.
  const std::string bag =
      Write("bag", Ros2Storage::kSqlite3, Ros2Compression::kNone, Messages(5, 1));
  const std::string file = bag + "/bag_0.db3";
  ASSERT_EQ(sqlite3_open(file.c_str(), &h), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(h, "UPDATE messages SET topic_id = 42 WHERE id = 3;", nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(h);
  EXPECT_NE(ReadError(file).find("topic_id 42"), std::string::npos) << ReadError(file);
}

TEST_F(Ros2BagTest, TruncatedSqliteIsAnErrorNamingTheFileOrReadsWhatIsLeft) {
  const std::string bag =
      Write("bag", Ros2Storage::kSqlite3, Ros2Compression::kNone, Messages(10, 5));
  const std::string good = Bytes(bag + "/bag_0.db3");
  const std::string cut = (dir_ / "cut.db3").string();
  for (size_t n = 0; n < good.size(); n += good.size() / 100 + 1) {
    Put(cut, good.substr(0, n));
    try {
      Ros2BagReader r(cut);
      ReadAll(r);
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(cut), std::string::npos) << e.what();
    }
  }
}

TEST_F(Ros2BagTest, WriterRefusesAnExistingFolderWithFiles) {
  fs::create_directories(dir_ / "full");
  Put((dir_ / "full/x").string(), "x");
  EXPECT_THROW(Ros2BagWriter((dir_ / "full").string(), Ros2Storage::kMcap), std::runtime_error);
  EXPECT_THROW(Ros2BagWriter((dir_ / "s").string(), Ros2Storage::kSqlite3, Ros2Compression::kZstd),
               std::runtime_error);
}

}  // namespace
}  // namespace ctlio::io::ros2::testing
