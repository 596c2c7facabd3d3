// Little-endian byte encoding for grid files and grid-set manifests. Every read checks the remaining length before
// touching memory, so a truncated or corrupt file can only ever throw InputError naming the file and byte offset.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "vox/core/error.h"
#include "vox/core/math.h"

namespace vox {

// Encodes values into bytes kept in memory (bytes()), or, when given a sink, hands them on in chunks of about
// kChunkBytes, so that writing a large grid file never holds the whole file in memory.
class ByteWriter {
 public:
  using Sink = std::function<void(std::string_view)>;
  static constexpr size_t kChunkBytes = size_t(1) << 16;

  ByteWriter() = default;
  explicit ByteWriter(Sink sink) : sink_(std::move(sink)) {}

  template <typename T>
  void put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    putBytes({reinterpret_cast<const char*>(&value), sizeof(T)});
  }
  void putVec(const Vec3& v) {
    put(v.x);
    put(v.y);
    put(v.z);
  }
  void putString(const std::string& s) {
    put(uint32_t(s.size()));
    putBytes(s);
  }
  template <typename T, typename A>
  void putArray(const std::vector<T, A>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    put(uint64_t(values.size()));
    putBytes({reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)});
  }
  void putBytes(std::string_view bytes) {
    if (sink_ && bytes.size() >= kChunkBytes) {  // large arrays go straight to the sink, uncopied
      finish();
      sink_(bytes);
      return;
    }
    out_.append(bytes);
    if (sink_ && out_.size() >= kChunkBytes) finish();
  }
  // Hands what is buffered to the sink (call once at the end); no-op without a sink.
  void finish() {
    if (sink_ && !out_.empty()) sink_(out_);
    if (sink_) out_.clear();
  }
  // The bytes so far; only meaningful without a sink.
  std::string& bytes() { return out_; }

 private:
  Sink sink_;
  std::string out_;
};

class ByteReader {
 public:
  ByteReader(const std::string& bytes, size_t offset, const std::string& name)
      : data_(bytes), pos_(offset), name_(name) {}

  [[noreturn]] void corrupt(const std::string& what) const { fail<InputError>(name_, ": byte ", pos_, ": ", what); }

  void need(uint64_t n) const {
    if (n > data_.size() - pos_)
      fail<InputError>(name_, ": truncated at byte ", data_.size(), " (needed ", n, " more bytes at byte ", pos_, ")");
  }
  template <typename T>
  T get() {
    need(sizeof(T));
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return value;
  }
  double getFinite(const char* what) {
    const double v = get<double>();
    if (!std::isfinite(v)) corrupt(std::string(what) + " is not a finite number");
    return v;
  }
  Vec3 getVec(const char* what) {
    Vec3 v;
    v.x = getFinite(what);
    v.y = getFinite(what);
    v.z = getFinite(what);
    return v;
  }
  std::string getString() {
    const uint32_t n = get<uint32_t>();
    need(n);
    std::string s = data_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  // A count of elements of `elementSize` bytes each that must fit in the rest of the file: refuses absurd counts
  // before anything is allocated.
  uint64_t getCount(size_t elementSize, const char* what) {
    const uint64_t n = get<uint64_t>();
    if (n > (data_.size() - pos_) / elementSize)
      corrupt(std::string(what) + " count " + std::to_string(n) + " exceeds the file");
    return n;
  }
  template <typename T, typename Array = std::vector<T>>
  Array getArray(const char* what) {
    const uint64_t n = getCount(sizeof(T), what);
    Array values(n);
    if (n > 0) std::memcpy(values.data(), data_.data() + pos_, n * sizeof(T));  // data() may be null when empty
    pos_ += n * sizeof(T);
    return values;
  }
  // The next n bytes, uncopied (they live as long as the reader's bytes).
  std::string_view take(uint64_t n) {
    need(n);
    const std::string_view bytes(data_.data() + pos_, n);
    pos_ += n;
    return bytes;
  }
  size_t position() const { return pos_; }
  size_t remaining() const { return data_.size() - pos_; }
  const std::string& name() const { return name_; }
  bool atEnd() const { return pos_ == data_.size(); }

 private:
  const std::string& data_;
  size_t pos_;
  std::string name_;  // a copy: callers pass literals and temporaries
};

}  // namespace vox
