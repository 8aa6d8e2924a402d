#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <ros/time.h>

namespace steadiface_bag {

/// A reader for indexed ROS bag files (format 2.0) that yields the messages
/// of the chosen topics in exactly rosbag::View's order, with less work per
/// message:
///  - the index is read from a memory map of the file, which is dropped
///    once Open() is done; each chunk is then read with one pread() into a
///    buffer that is reused (a mapped chunk costs a page fault per 16
///    pages on first touch: 0.43 s against 0.07 s for the 630 MB of the
///    speed protocol's clip, see docs/benchmarks.md), and a file that is
///    truncated while it is read gives an error that says so;
///  - an LZ4 chunk is decompressed once by liblz4's frame decoder, by
///    default with its checksums skipped (rosbag's roslz4 computes XXH32
///    over every byte, which costs as much as the decompression itself).
///    Without the checksum a corrupt chunk is still bounded: every record
///    is checked against its chunk, and a chunk whose LZ4 stream does not
///    decode to its stated size is an error; but damage that still decodes
///    yields damaged message bytes, which rosbag would have refused;
///  - nothing is deserialized here: the caller deserializes the message
///    bytes into the type it wants.
///
/// The order is rosbag::View's: the bag's own index (the connection-index
/// records after each chunk) is read into one time-ordered multiset per
/// connection, and they are merged with View's algorithm (ranges in
/// connection-id order, re-sorted by time after every step), so ties
/// between connections come out as they do from View.
///
/// It handles what `rosbag record` and rosbag::Bag write: version 2.0,
/// indexed, not encrypted, chunks stored uncompressed or LZ4. Open() says
/// why it will not read anything else (BZ2 chunks, an encrypted or
/// unindexed bag, version 1.2), and the caller falls back to rosbag::View.
class IndexedBagReader {
 public:
  struct Connection {
    std::string topic;
    std::string datatype;
  };
  /// One message. `data` stays valid until the next call to Next() or
  /// Select() (it points into the chunk buffer).
  struct Message {
    uint32_t connection = 0;
    ros::Time time;
    const uint8_t* data = nullptr;
    uint32_t size = 0;
  };

  /// `verify_checksums`: check each LZ4 frame's XXH32 checksums, as rosbag
  /// does (an error on a mismatch; costs about as much as decompressing).
  /// LZ4 older than 1.9.4 (Noetic's generation) always checks them.
  explicit IndexedBagReader(bool verify_checksums = false);
  ~IndexedBagReader();
  IndexedBagReader(const IndexedBagReader&) = delete;
  IndexedBagReader& operator=(const IndexedBagReader&) = delete;

  /// Opens `path` and reads its index. False, with the reason in *why, if
  /// the file cannot be opened or is a bag this reader does not handle.
  bool Open(const std::string& path, std::string* why);
  /// Connection id -> topic and type, for every connection in the bag.
  const std::map<uint32_t, Connection>& connections() const {
    return connections_;
  }
  /// The number of messages whose connection's topic is one of `topics`
  /// (as rosbag::View(bag, TopicQuery(topics)).size()).
  size_t Count(const std::vector<std::string>& topics) const;
  /// Iterates the messages whose connection's topic is one of `topics`
  /// (compared as stored in the bag), from the first.
  void Select(const std::vector<std::string>& topics);
  /// The next message in View's order. False at the end, or on corrupt
  /// data with *error set (then the iteration stops).
  bool Next(Message* m, std::string* error);
  /// How many times a chunk was read (and decompressed) since Open().
  size_t chunks_read() const { return chunks_read_; }
  /// The number of chunks in the bag.
  size_t chunk_count() const { return chunks_.size(); }

 private:
  struct IndexEntry {
    ros::Time time;
    uint64_t chunk_pos = 0;
    uint32_t offset = 0;
    bool operator<(const IndexEntry& b) const { return time < b.time; }
  };
  using Index = std::multiset<IndexEntry>;
  struct Range {
    Index::const_iterator begin, end;
    uint32_t connection = 0;
  };
  struct Cursor {
    Index::const_iterator iter;
    const Range* range = nullptr;
  };
  struct Chunk {
    std::string compression;
    uint32_t size = 0;         // uncompressed
    uint64_t data_offset = 0;  // of the stored bytes, in the file
    uint32_t stored_size = 0;
  };

  bool ReadIndex(std::string* why);
  // ReadIndex's steps: the file header (where the index is, what it
  // holds), the connection records and chunk infos from *pos on, and one
  // chunk with its connection index records.
  bool ReadFileHeader(std::string* why, uint64_t* index_pos, uint32_t* conn_count,
                      uint32_t* chunk_count);
  bool ReadConnections(uint32_t count, uint64_t* pos, std::string* why);
  bool ReadChunkInfos(uint32_t count, uint64_t* pos,
                      std::vector<std::pair<uint64_t, uint32_t>>* chunk_infos, std::string* why);
  bool ReadChunk(uint64_t chunk_pos, uint32_t connections, std::string* why);
  /// The chunk at `pos`'s records, read and decompressed; null with
  /// *error on failure.
  const uint8_t* ChunkData(uint64_t pos, uint32_t* size, std::string* error);
  /// Reads `size` bytes at `offset` of the file into `out`.
  bool ReadAt(uint64_t offset, uint32_t size, uint8_t* out,
              std::string* error) const;
  void Unmap();
  void CloseFile();

  int fd_ = -1;
  const uint8_t* file_ = nullptr;  // the map, during Open() only
  uint64_t file_size_ = 0;
  std::map<uint32_t, Connection> connections_;
  std::map<uint32_t, Index> indexes_;
  std::map<uint64_t, Chunk> chunks_;  // by file position
  std::vector<Range> ranges_;
  std::vector<Cursor> cursors_;
  const bool verify_checksums_;
  bool started_ = false;
  // The two chunks read last, decompressed. View's order can go back and
  // forth between neighbouring chunks where their times meet (in bags
  // written by steadiface_simulate it did at every chunk boundary, and with
  // one chunk kept every chunk was read and decompressed twice); otherwise
  // it reads a chunk's messages together.
  struct CachedChunk {
    uint64_t pos = UINT64_MAX;
    std::vector<uint8_t> data;
  };
  CachedChunk cached_[2];
  int last_cached_ = 0;  // the slot used last
  size_t chunks_read_ = 0;
  std::vector<uint8_t> stored_;  // an LZ4 chunk's bytes as stored
  struct Lz4Context;
  std::unique_ptr<Lz4Context> lz4_;
};

}  // namespace steadiface_bag
