// rosbag2's SQLite 3 storage (the `sqlite3` storage plugin's schema): tables
//   topics(id INTEGER PRIMARY KEY, name, type, serialization_format, offered_qos_profiles)
//   messages(id INTEGER PRIMARY KEY, topic_id, timestamp, data)
// and, since schema version 3, schema(schema_version, ros_distro). Read through the sqlite3 C API
// read-only; older files without serialization_format or the schema table are read too.
//
// Reading sorts (timestamp, rowid) pairs only, then fetches each row's data by its rowid: SQLite's
// sorter never holds the message bytes, and memory stays one row.
#include <sqlite3.h>

#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>

#include "storage.h"

namespace ctlio::io::ros2 {
namespace {

class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::string& path) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK) {
      const std::string msg = sqlite3_errmsg(db);
      sqlite3_finalize(stmt_);
      stmt_ = nullptr;
      throw std::runtime_error(path + ": SQLite: " + msg + " (in `" + sql + "`)");
    }
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() const { return stmt_; }

 private:
  sqlite3_stmt* stmt_ = nullptr;
};

std::set<std::string> Columns(sqlite3* db, const std::string& table, const std::string& path) {
  Statement s(db, "PRAGMA table_info(" + table + ")", path);
  std::set<std::string> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    const unsigned char* name = sqlite3_column_text(s.get(), 1);
    if (name) out.insert(reinterpret_cast<const char*>(name));
  }
  return out;
}

std::string Text(sqlite3_stmt* s, int column) {
  const unsigned char* t = sqlite3_column_text(s, column);
  return t ? std::string(reinterpret_cast<const char*>(t), sqlite3_column_bytes(s, column)) : "";
}

class SqliteReader : public StorageReader {
 public:
  explicit SqliteReader(const std::string& path) : path_(path) {
    if (!HasSqliteHeader(path)) throw std::runtime_error(path + ": not an SQLite 3 file");
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      throw std::runtime_error(path + ": cannot open as SQLite: " + msg);
    }
    try {
      const std::set<std::string> topic_columns = Columns(db_, "topics", path);
      const std::set<std::string> message_columns = Columns(db_, "messages", path);
      for (const char* c : {"id", "name", "type"}) {
        if (!topic_columns.count(c)) Missing("topics", c);
      }
      for (const char* c : {"topic_id", "timestamp", "data"}) {
        if (!message_columns.count(c)) Missing("messages", c);
      }
      const bool has_format = topic_columns.count("serialization_format") > 0;
      Statement s(db_,
                  std::string("SELECT id, name, type") +
                      (has_format ? ", serialization_format" : "") + " FROM topics ORDER BY id",
                  path);
      int rc;
      while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
        const int64_t id = sqlite3_column_int64(s.get(), 0);
        Ros2Topic t{Text(s.get(), 1), Text(s.get(), 2), has_format ? Text(s.get(), 3) : "cdr", 0};
        size_t i = 0;
        while (i < topics_.size() && topics_[i].name != t.name) ++i;
        if (i == topics_.size()) {
          topics_.push_back(t);
        } else if (topics_[i].type != t.type) {
          throw std::runtime_error(path + ": topic '" + t.name + "' listed with types '" +
                                   topics_[i].type + "' and '" + t.type + "'");
        }
        topic_of_id_[id] = i;
      }
      if (rc != SQLITE_DONE) Fail("reading the topics table");
    } catch (...) {
      sqlite3_close(db_);
      throw;
    }
    wanted_.assign(topics_.size(), true);
  }
  ~SqliteReader() override {
    rows_.reset();
    data_.reset();
    sqlite3_close(db_);
  }

  const std::vector<Ros2Topic>& topics() const override { return topics_; }
  void SetFilter(const std::vector<bool>& wanted) override { wanted_ = wanted; }

  bool Next(Ros2Message* message) override {
    if (!rows_) Prepare();
    const int rc = sqlite3_step(rows_->get());
    if (rc == SQLITE_DONE) return false;
    if (rc != SQLITE_ROW) Fail("reading the messages table");
    row_ = sqlite3_column_int64(rows_->get(), 0);
    const int64_t topic_id = sqlite3_column_int64(rows_->get(), 1);
    if (sqlite3_column_type(rows_->get(), 2) != SQLITE_INTEGER) {
      throw std::runtime_error(Where() + ": timestamp is not an integer");
    }
    const auto it = topic_of_id_.find(topic_id);
    if (it == topic_of_id_.end()) {
      throw std::runtime_error(Where() + ": topic_id " + std::to_string(topic_id) +
                               " is not in the topics table");
    }
    message->topic = it->second;
    message->log_time_ns = sqlite3_column_int64(rows_->get(), 2);
    sqlite3_stmt* d = data_->get();
    sqlite3_reset(d);
    sqlite3_bind_int64(d, 1, row_);
    if (sqlite3_step(d) != SQLITE_ROW)
      Fail("reading the data of message row " + std::to_string(row_));
    if (sqlite3_column_type(d, 0) == SQLITE_NULL) {
      throw std::runtime_error(Where() + ": data is NULL");
    }
    const void* blob = sqlite3_column_blob(d, 0);
    const int n = sqlite3_column_bytes(d, 0);
    const auto* p = static_cast<const uint8_t*>(blob);
    message->data.assign(p, p + (p ? n : 0));
    return true;
  }

  std::string Where() const override {
    return path_ + ": messages row with id " + std::to_string(row_);
  }

 private:
  [[noreturn]] void Missing(const char* table, const char* column) const {
    throw std::runtime_error(path_ + ": an SQLite file but not a rosbag2 bag: no column '" +
                             column + "' in a table '" + table + "'");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": SQLite error " + what + ": " + sqlite3_errmsg(db_));
  }
  void Prepare() {
    std::string where;
    for (const auto& [id, topic] : topic_of_id_) {
      if (!wanted_[topic]) continue;
      where += (where.empty() ? "" : ",") + std::to_string(id);
    }
    // Every topic wanted: no filter, so rows of topic ids missing from `topics` are reported.
    bool all = true;
    for (bool w : wanted_) all = all && w;
    const std::string filter = all ? "" : " WHERE topic_id IN (" + where + ")";
    rows_ = std::make_unique<Statement>(
        db_,
        "SELECT rowid, topic_id, timestamp FROM messages" + filter + " ORDER BY timestamp, rowid",
        path_);
    data_ = std::make_unique<Statement>(db_, "SELECT data FROM messages WHERE rowid = ?", path_);
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::vector<Ros2Topic> topics_;
  std::map<int64_t, size_t> topic_of_id_;
  std::vector<bool> wanted_;
  std::unique_ptr<Statement> rows_, data_;
  int64_t row_ = 0;
};

class SqliteWriter : public StorageWriter {
 public:
  explicit SqliteWriter(const std::string& path) : path_(path) {
    if (sqlite3_open_v2(path.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
        SQLITE_OK) {
      const std::string msg = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw std::runtime_error(path + ": cannot create: " + msg);
    }
    // As rosbag2's sqlite3 plugin writes (schema version 3).
    Exec(
        "PRAGMA journal_mode=MEMORY; PRAGMA synchronous=OFF;"
        "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
        "INSERT INTO schema VALUES(3, 'humble');"
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
        " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
        " timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
        "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
        "BEGIN TRANSACTION;");
    insert_ = std::make_unique<Statement>(
        db_, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", path_);
  }
  ~SqliteWriter() override {
    insert_.reset();
    if (db_) sqlite3_close(db_);
  }

  void AddTopic(size_t index, const std::string& name, const std::string& type) override {
    Statement s(db_,
                "INSERT INTO topics (id, name, type, serialization_format, offered_qos_profiles) "
                "VALUES (?, ?, ?, 'cdr', '')",
                path_);
    sqlite3_bind_int64(s.get(), 1, static_cast<int64_t>(index) + 1);
    sqlite3_bind_text(s.get(), 2, name.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.get(), 3, type.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(s.get()) != SQLITE_DONE) Fail("adding topic " + name);
  }

  void Write(size_t topic, int64_t log_time_ns, const std::vector<uint8_t>& data) override {
    sqlite3_stmt* s = insert_->get();
    sqlite3_reset(s);
    sqlite3_bind_int64(s, 1, static_cast<int64_t>(topic) + 1);
    sqlite3_bind_int64(s, 2, log_time_ns);
    // A zero-length blob must still be a BLOB (NOT NULL): bind a non-null pointer.
    static const uint8_t kEmpty = 0;
    sqlite3_bind_blob64(s, 3, data.empty() ? &kEmpty : data.data(), data.size(), SQLITE_STATIC);
    if (sqlite3_step(s) != SQLITE_DONE) Fail("writing a message");
    // Commits every 1000 messages: the journal (in memory) stays small.
    if (++pending_ % 1000 == 0) Exec("COMMIT; BEGIN TRANSACTION;");
  }

  void Close() override {
    insert_.reset();
    Exec("COMMIT;");
    if (sqlite3_close(db_) != SQLITE_OK) Fail("closing");
    db_ = nullptr;
  }

 private:
  void Exec(const char* sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql, nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string msg = err ? err : "unknown";
      sqlite3_free(err);
      throw std::runtime_error(path_ + ": SQLite: " + msg);
    }
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": SQLite error " + what + ": " + sqlite3_errmsg(db_));
  }

  std::string path_;
  sqlite3* db_ = nullptr;
  std::unique_ptr<Statement> insert_;
  uint64_t pending_ = 0;
};

}  // namespace

bool HasSqliteHeader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[16] = {};
  return in.read(head, 16) && std::memcmp(head, "SQLite format 3\0", 16) == 0;
}

bool IsRosbag2Sqlite(const std::string& path) {
  try {
    SqliteReader reader(path);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

std::unique_ptr<StorageReader> OpenSqlite(const std::string& path) {
  return std::make_unique<SqliteReader>(path);
}

std::unique_ptr<StorageWriter> CreateSqlite(const std::string& path) {
  return std::make_unique<SqliteWriter>(path);
}

}  // namespace ctlio::io::ros2
