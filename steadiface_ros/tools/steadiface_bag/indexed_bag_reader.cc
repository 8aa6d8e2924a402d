#include "steadiface_bag/indexed_bag_reader.h"

#include <fcntl.h>
#include <lz4.h>
#include <lz4frame.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace steadiface_bag {
namespace {

// Record op codes of the bag format 2.0.
constexpr uint8_t kOpMessageDefinition = 0x01;  // version 1.2 only
constexpr uint8_t kOpMessageData = 0x02;
constexpr uint8_t kOpFileHeader = 0x03;
constexpr uint8_t kOpIndexData = 0x04;
constexpr uint8_t kOpChunk = 0x05;
constexpr uint8_t kOpChunkInfo = 0x06;
constexpr uint8_t kOpConnection = 0x07;
constexpr char kVersionLine[] = "#ROSBAG V2.0\n";

uint32_t U32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}

// One record: header fields, and the data after them.
struct Record {
  std::map<std::string, std::string> fields;
  const uint8_t* data = nullptr;
  uint32_t data_size = 0;
  uint64_t total_size = 0;  // both length words, header and data

  bool Has(const char* name) const { return fields.count(name) != 0; }
  bool Op(uint8_t* op) const {
    auto it = fields.find("op");
    if (it == fields.end() || it->second.size() != 1) return false;
    *op = static_cast<uint8_t>(it->second[0]);
    return true;
  }
  bool Uint32(const char* name, uint32_t* v) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != 4) return false;
    std::memcpy(v, it->second.data(), 4);
    return true;
  }
  bool Uint64(const char* name, uint64_t* v) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != 8) return false;
    std::memcpy(v, it->second.data(), 8);
    return true;
  }
  bool Time(const char* name, ros::Time* t) const {
    auto it = fields.find(name);
    if (it == fields.end() || it->second.size() != 8) return false;
    const uint8_t* p = reinterpret_cast<const uint8_t*>(it->second.data());
    *t = ros::Time(U32(p), U32(p + 4));
    return true;
  }
  bool String(const char* name, std::string* s) const {
    auto it = fields.find(name);
    if (it == fields.end()) return false;
    *s = it->second;
    return true;
  }
};

// "name=value" fields, each behind its 32-bit length.
bool ParseFields(const uint8_t* p, uint64_t size,
                 std::map<std::string, std::string>* fields) {
  uint64_t q = 0;
  while (q < size) {
    if (size - q < 4) return false;
    const uint32_t len = U32(p + q);
    q += 4;
    if (len > size - q) return false;
    const char* f = reinterpret_cast<const char*>(p + q);
    const char* eq = static_cast<const char*>(std::memchr(f, '=', len));
    if (eq == nullptr) return false;
    (*fields)[std::string(f, eq)] = std::string(eq + 1, f + len);
    q += len;
  }
  return true;
}

// The record at `pos` of a buffer of `size` bytes.
bool ParseRecord(const uint8_t* buf, uint64_t size, uint64_t pos, Record* r) {
  if (pos > size || size - pos < 4) return false;
  const uint32_t header_len = U32(buf + pos);
  uint64_t q = pos + 4;
  if (header_len > size - q) return false;
  const uint8_t* header = buf + q;
  q += header_len;
  if (size - q < 4) return false;
  const uint32_t data_len = U32(buf + q);
  q += 4;
  if (data_len > size - q) return false;
  r->fields.clear();
  if (!ParseFields(header, header_len, &r->fields)) return false;
  r->data = buf + q;
  r->data_size = data_len;
  r->total_size = 8ull + header_len + data_len;
  return true;
}

}  // namespace

struct IndexedBagReader::Lz4Context {
  LZ4F_dctx* ctx = nullptr;
  Lz4Context() { LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION); }
  ~Lz4Context() { LZ4F_freeDecompressionContext(ctx); }
};

IndexedBagReader::IndexedBagReader(bool verify_checksums)
    : verify_checksums_(verify_checksums), lz4_(new Lz4Context) {}

IndexedBagReader::~IndexedBagReader() {
  Unmap();
  CloseFile();
}

void IndexedBagReader::Unmap() {
  if (file_ != nullptr) munmap(const_cast<uint8_t*>(file_), file_size_);
  file_ = nullptr;
}

void IndexedBagReader::CloseFile() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  file_size_ = 0;
}

bool IndexedBagReader::Open(const std::string& path, std::string* why) {
  Unmap();
  CloseFile();
  connections_.clear();
  indexes_.clear();
  chunks_.clear();
  ranges_.clear();
  cursors_.clear();
  started_ = false;
  for (CachedChunk& c : cached_) c.pos = UINT64_MAX;
  chunks_read_ = 0;
  if (lz4_->ctx == nullptr) {
    *why = "no LZ4 decompression context";
    return false;
  }
  fd_ = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) {
    *why = "cannot open " + path + ": " + std::strerror(errno);
    return false;
  }
  struct stat st;
  if (fstat(fd_, &st) != 0 || st.st_size <= 0) {
    CloseFile();
    *why = "cannot size " + path;
    return false;
  }
  file_size_ = static_cast<uint64_t>(st.st_size);
  // The index is read through a map (its records lie after every chunk),
  // the chunks later with pread().
  void* m = mmap(nullptr, file_size_, PROT_READ, MAP_PRIVATE, fd_, 0);
  if (m == MAP_FAILED) {
    *why = "cannot map " + path + ": " + std::strerror(errno);
    CloseFile();
    return false;
  }
  file_ = static_cast<const uint8_t*>(m);
  madvise(m, file_size_, MADV_RANDOM);
  bool ok = false;
  try {
    ok = ReadIndex(why);
  } catch (const std::exception& e) {  // ros::Time out of range, no memory
    *why = std::string("bad index: ") + e.what();
  }
  Unmap();
  if (!ok) {
    CloseFile();
    connections_.clear();
    indexes_.clear();
    chunks_.clear();
    return false;
  }
  // The chunks are read in order, mostly: let the kernel read ahead.
  posix_fadvise(fd_, 0, 0, POSIX_FADV_SEQUENTIAL);
  return true;
}

bool IndexedBagReader::ReadAt(uint64_t offset, uint32_t size, uint8_t* out,
                              std::string* error) const {
  uint64_t done = 0;
  while (done < size) {
    const ssize_t n = pread(fd_, out + done, size - done,
                            static_cast<off_t>(offset + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      *error = std::string("cannot read a chunk: ") + std::strerror(errno);
      return false;
    }
    if (n == 0) {
      *error = "the bag ends inside a chunk (truncated while read?)";
      return false;
    }
    done += static_cast<uint64_t>(n);
  }
  return true;
}

bool IndexedBagReader::ReadFileHeader(std::string* why, uint64_t* index_pos,
                                      uint32_t* conn_count, uint32_t* chunk_count) {
  const size_t vlen = sizeof(kVersionLine) - 1;
  if (file_size_ < vlen || std::memcmp(file_, kVersionLine, vlen) != 0) {
    *why = "not a version 2.0 bag";
    return false;
  }
  Record r;
  uint8_t op = 0;
  if (!ParseRecord(file_, file_size_, vlen, &r) || !r.Op(&op) ||
      op != kOpFileHeader) {
    *why = "no bag header record";
    return false;
  }
  if (!r.Uint64("index_pos", index_pos) ||
      !r.Uint32("conn_count", conn_count) ||
      !r.Uint32("chunk_count", chunk_count)) {
    *why = "bag header without index_pos/conn_count/chunk_count";
    return false;
  }
  std::string encryptor;
  if (r.String("encryptor", &encryptor) && !encryptor.empty() &&
      encryptor != "rosbag/NoEncryptor") {
    *why = "encrypted bag (" + encryptor + ")";
    return false;
  }
  if (*index_pos == 0 || *index_pos >= file_size_) {
    *why = "unindexed bag (rosbag reindex it)";
    return false;
  }
  return true;
}

bool IndexedBagReader::ReadConnections(uint32_t count, uint64_t* pos, std::string* why) {
  Record r;
  uint8_t op = 0;
  for (uint32_t i = 0; i < count; ++i) {
    uint32_t id = 0;
    Connection c;
    std::map<std::string, std::string> conn_header;
    if (!ParseRecord(file_, file_size_, *pos, &r) || !r.Op(&op) ||
        op != kOpConnection || !r.Uint32("conn", &id) ||
        !r.String("topic", &c.topic) ||
        !ParseFields(r.data, r.data_size, &conn_header)) {
      *why = "bad connection record in the index";
      return false;
    }
    auto type = conn_header.find("type");
    if (type != conn_header.end()) c.datatype = type->second;
    connections_[id] = c;
    *pos += r.total_size;
  }
  return true;
}

bool IndexedBagReader::ReadChunkInfos(uint32_t count, uint64_t* pos,
                                      std::vector<std::pair<uint64_t, uint32_t>>* chunk_infos,
                                      std::string* why) {
  Record r;
  uint8_t op = 0;
  for (uint32_t i = 0; i < count; ++i) {
    uint64_t chunk_pos = 0;
    uint32_t connections = 0;
    if (!ParseRecord(file_, file_size_, *pos, &r) || !r.Op(&op) ||
        op != kOpChunkInfo || !r.Uint64("chunk_pos", &chunk_pos) ||
        !r.Uint32("count", &connections)) {
      *why = "bad chunk info record in the index";
      return false;
    }
    chunk_infos->emplace_back(chunk_pos, connections);
    *pos += r.total_size;
  }
  return true;
}

bool IndexedBagReader::ReadChunk(uint64_t chunk_pos, uint32_t connections, std::string* why) {
  Record r;
  uint8_t op = 0;
  Chunk chunk;
  if (!ParseRecord(file_, file_size_, chunk_pos, &r) || !r.Op(&op) ||
      op != kOpChunk || !r.String("compression", &chunk.compression) ||
      !r.Uint32("size", &chunk.size)) {
    *why = "bad chunk record";
    return false;
  }
  if (chunk.compression != "none" && chunk.compression != "lz4") {
    *why = "chunks compressed with " + chunk.compression;
    return false;
  }
  chunk.data_offset = static_cast<uint64_t>(r.data - file_);
  chunk.stored_size = r.data_size;
  if (chunk.compression == "none" && chunk.size != chunk.stored_size) {
    *why = "uncompressed chunk of the wrong size";
    return false;
  }
  // LZ4 expands at most 255-fold (a match's length costs at least one byte
  // per 255): a larger stated size is damage, refused here rather than
  // allocated and cleared when the chunk is read.
  if (chunk.compression == "lz4" &&
      chunk.size > 255ull * chunk.stored_size + 65536) {
    *why = "LZ4 chunk states an impossible size";
    return false;
  }
  uint64_t q = chunk_pos + r.total_size;
  for (uint32_t k = 0; k < connections; ++k) {
    uint32_t ver = 0, conn = 0, count = 0;
    if (!ParseRecord(file_, file_size_, q, &r) || !r.Op(&op) ||
        op != kOpIndexData || !r.Uint32("ver", &ver) || ver != 1 ||
        !r.Uint32("conn", &conn) || !r.Uint32("count", &count) ||
        r.data_size / 12 < count) {
      *why = "bad connection index record";
      return false;
    }
    Index& index = indexes_[conn];
    for (uint32_t e = 0; e < count; ++e) {
      const uint8_t* p = r.data + 12ull * e;
      IndexEntry entry;
      entry.time = ros::Time(U32(p), U32(p + 4));
      entry.chunk_pos = chunk_pos;
      entry.offset = U32(p + 8);
      if (entry.offset >= chunk.size) {
        *why = "index entry outside its chunk";
        return false;
      }
      index.insert(index.end(), entry);
    }
    q += r.total_size;
  }
  chunks_[chunk_pos] = chunk;
  return true;
}

bool IndexedBagReader::ReadIndex(std::string* why) {
  uint64_t index_pos = 0;
  uint32_t conn_count = 0, chunk_count = 0;
  if (!ReadFileHeader(why, &index_pos, &conn_count, &chunk_count)) return false;
  // Connection records, then chunk info records, at index_pos.
  uint64_t pos = index_pos;
  std::vector<std::pair<uint64_t, uint32_t>> chunk_infos;  // position, connections
  if (!ReadConnections(conn_count, &pos, why) ||
      !ReadChunkInfos(chunk_count, &pos, &chunk_infos, why)) {
    return false;
  }
  // Each chunk, and the connection index records right after it: one
  // multiset per connection, filled in chunk order as rosbag does.
  for (const auto& ci : chunk_infos) {
    if (!ReadChunk(ci.first, ci.second, why)) return false;
  }
  return true;
}

size_t IndexedBagReader::Count(const std::vector<std::string>& topics) const {
  size_t n = 0;
  for (const auto& c : connections_) {
    if (std::find(topics.begin(), topics.end(), c.second.topic) == topics.end())
      continue;
    auto it = indexes_.find(c.first);
    if (it != indexes_.end()) n += it->second.size();
  }
  return n;
}

void IndexedBagReader::Select(const std::vector<std::string>& topics) {
  ranges_.clear();
  cursors_.clear();
  started_ = false;
  // View::updateQueries: connections in id order, those with an index.
  for (const auto& c : connections_) {
    if (std::find(topics.begin(), topics.end(), c.second.topic) == topics.end())
      continue;
    auto it = indexes_.find(c.first);
    if (it == indexes_.end() || it->second.empty()) continue;
    ranges_.push_back(Range{it->second.begin(), it->second.end(), c.first});
  }
}

const uint8_t* IndexedBagReader::ChunkData(uint64_t pos, uint32_t* size,
                                           std::string* error) {
  auto it = chunks_.find(pos);
  if (it == chunks_.end()) {
    *error = "index points to no chunk";
    return nullptr;
  }
  const Chunk& c = it->second;
  *size = c.size;
  for (int i = 0; i < 2; ++i) {
    if (cached_[i].pos == pos) {
      last_cached_ = i;
      return cached_[i].data.data();
    }
  }
  // Into the slot not used last (the message handed out before this call
  // is no longer valid, whichever slot it was in).
  last_cached_ = 1 - last_cached_;
  CachedChunk& slot = cached_[last_cached_];
  slot.pos = UINT64_MAX;
  slot.data.resize(c.size);
  ++chunks_read_;
  if (c.compression == "none") {
    if (!ReadAt(c.data_offset, c.stored_size, slot.data.data(), error)) {
      return nullptr;
    }
    slot.pos = pos;
    return slot.data.data();
  }
  stored_.resize(c.stored_size);
  if (!ReadAt(c.data_offset, c.stored_size, stored_.data(), error)) {
    return nullptr;
  }
  LZ4F_decompressOptions_t options;
  std::memset(&options, 0, sizeof(options));
#if LZ4_VERSION_NUMBER >= 10904  // skipChecksums is new in LZ4 1.9.4
  options.skipChecksums = verify_checksums_ ? 0 : 1;
#endif  // older LZ4 (Ubuntu 20.04's 1.9.2, Debian 11's 1.9.3) always checks them
  size_t out = 0, in = 0;
  size_t hint = 1;
  // One frame per chunk; the loop covers a decoder that stops early.
  while (hint != 0 && in < c.stored_size && out < c.size) {
    size_t dst = c.size - out, src = c.stored_size - in;
    hint = LZ4F_decompress(lz4_->ctx, slot.data.data() + out, &dst, stored_.data() + in,
                           &src, &options);
    if (LZ4F_isError(hint)) {
      *error = std::string("LZ4 chunk: ") + LZ4F_getErrorName(hint);
      LZ4F_resetDecompressionContext(lz4_->ctx);
      return nullptr;
    }
    out += dst;
    in += src;
    if (dst == 0 && src == 0) break;
  }
  LZ4F_resetDecompressionContext(lz4_->ctx);
  if (out != c.size) {
    *error = "LZ4 chunk decompressed to the wrong size";
    return nullptr;
  }
  slot.pos = pos;
  return slot.data.data();
}

bool IndexedBagReader::Next(Message* m, std::string* error) {
  error->clear();
  // View::iterator: the cursor with the earliest time is the last one after
  // a sort by descending time; advance it, drop it at its end, sort again.
  auto later = [](const Cursor& a, const Cursor& b) {
    return a.iter->time > b.iter->time;
  };
  if (!started_) {
    started_ = true;
    for (const Range& r : ranges_) {
      if (r.begin != r.end) cursors_.push_back(Cursor{r.begin, &r});
    }
    std::sort(cursors_.begin(), cursors_.end(), later);
  } else if (!cursors_.empty()) {
    Cursor& back = cursors_.back();
    ++back.iter;
    if (back.iter == back.range->end) cursors_.pop_back();
    std::sort(cursors_.begin(), cursors_.end(), later);
  }
  if (cursors_.empty()) return false;
  const Cursor& cur = cursors_.back();
  uint32_t chunk_size = 0;
  const uint8_t* chunk = ChunkData(cur.iter->chunk_pos, &chunk_size, error);
  if (chunk == nullptr) {
    cursors_.clear();
    return false;
  }
  // The message data record at the offset (connection records before it
  // are skipped, as rosbag does).
  uint64_t q = cur.iter->offset;
  Record r;
  uint8_t op = 0;
  for (;;) {
    if (!ParseRecord(chunk, chunk_size, q, &r) || !r.Op(&op)) {
      *error = "bad record in a chunk";
      cursors_.clear();
      return false;
    }
    if (op != kOpConnection && op != kOpMessageDefinition) break;
    q += r.total_size;
  }
  if (op != kOpMessageData) {
    *error = "index entry does not point to a message";
    cursors_.clear();
    return false;
  }
  m->connection = cur.range->connection;
  m->time = cur.iter->time;
  m->data = r.data;
  m->size = r.data_size;
  return true;
}

}  // namespace steadiface_bag
