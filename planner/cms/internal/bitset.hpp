// Bitset: a dynamic set of small non-negative integers as 64-bit words, for the CMS's label sets,
// allowed-pair matrices and the ordering graph's transitive closure. A plain value (one vector).
//
// Invariant: bits at positions >= size() are zero, so word-wise comparisons, counts and
// intersection tests never see stray bits. Private to planner/cms/.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace spar::planner::cms::internal {

inline constexpr int kWordBits = 64;

[[nodiscard]] constexpr int words_for(int bits) { return (bits + kWordBits - 1) / kWordBits; }

// Word-span helpers shared by Bitset and the rows of a BitMatrix.
[[nodiscard]] inline bool spans_intersect(std::span<const std::uint64_t> a,
                                          std::span<const std::uint64_t> b) {
  for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) {
    if ((a[i] & b[i]) != 0) return true;
  }
  return false;
}

// Smallest set bit at position >= from, or -1. `bits` bounds the search.
[[nodiscard]] inline int span_find_next(std::span<const std::uint64_t> words, int bits, int from) {
  if (from < 0) from = 0;
  if (from >= bits) return -1;
  std::size_t word = static_cast<std::size_t>(from / kWordBits);
  std::uint64_t current = words[word] & (~std::uint64_t{0} << (from % kWordBits));
  while (true) {
    if (current != 0) {
      const int bit = static_cast<int>(word) * kWordBits + std::countr_zero(current);
      return bit < bits ? bit : -1;
    }
    if (++word >= words.size()) return -1;
    current = words[word];
  }
}

[[nodiscard]] inline bool span_test(std::span<const std::uint64_t> words, int bit) {
  return ((words[static_cast<std::size_t>(bit / kWordBits)] >> (bit % kWordBits)) & 1U) != 0;
}

// True if every bit set in `subset` is set in `superset` (spans of equal length).
[[nodiscard]] inline bool span_is_subset(std::span<const std::uint64_t> subset,
                                         std::span<const std::uint64_t> superset) {
  for (std::size_t i = 0; i < subset.size(); ++i) {
    if ((subset[i] & ~superset[i]) != 0) return false;
  }
  return true;
}

// destination |= source (spans of equal length).
inline void span_unite(std::span<std::uint64_t> destination,
                       std::span<const std::uint64_t> source) {
  for (std::size_t i = 0; i < destination.size(); ++i) destination[i] |= source[i];
}

class Bitset {
 public:
  Bitset() = default;
  explicit Bitset(int size) : size_{size}, words_(static_cast<std::size_t>(words_for(size)), 0) {}
  // A copy of words_for(size) words (a matrix row, say) as a set of `size` bits.
  Bitset(int size, std::span<const std::uint64_t> words)
      : size_{size}, words_(words.begin(), words.end()) {}

  [[nodiscard]] int size() const { return size_; }
  [[nodiscard]] bool test(int bit) const {
    return ((words_[static_cast<std::size_t>(bit / kWordBits)] >> (bit % kWordBits)) & 1U) != 0;
  }
  void set(int bit) {
    words_[static_cast<std::size_t>(bit / kWordBits)] |= std::uint64_t{1} << (bit % kWordBits);
  }
  void reset(int bit) {
    words_[static_cast<std::size_t>(bit / kWordBits)] &= ~(std::uint64_t{1} << (bit % kWordBits));
  }
  void clear() {
    for (std::uint64_t& word : words_) word = 0;
  }
  // Grows (new bits zero) or shrinks (dropped bits cleared, keeping the invariant).
  void resize(int size) {
    words_.resize(static_cast<std::size_t>(words_for(size)), 0);
    size_ = size;
    if (size_ % kWordBits != 0) words_.back() &= (std::uint64_t{1} << (size_ % kWordBits)) - 1;
  }

  [[nodiscard]] bool none() const {
    for (const std::uint64_t word : words_) {
      if (word != 0) return false;
    }
    return true;
  }
  [[nodiscard]] int count() const {
    int total = 0;
    for (const std::uint64_t word : words_) total += std::popcount(word);
    return total;
  }
  // Smallest member >= from, or -1.
  [[nodiscard]] int find_next(int from) const { return span_find_next(words_, size_, from); }
  [[nodiscard]] int find_first() const { return find_next(0); }

  [[nodiscard]] bool intersects(std::span<const std::uint64_t> other) const {
    return spans_intersect(words_, other);
  }
  [[nodiscard]] bool intersects(const Bitset& other) const { return intersects(other.words()); }
  // True if every member of this set is in `other` (same size).
  [[nodiscard]] bool is_subset_of(const Bitset& other) const {
    for (std::size_t i = 0; i < words_.size(); ++i) {
      if ((words_[i] & ~other.words_[i]) != 0) return false;
    }
    return true;
  }
  // this &= other (a row of the same width); returns true if this changed.
  bool intersect_with(std::span<const std::uint64_t> other) {
    bool changed = false;
    for (std::size_t i = 0; i < words_.size(); ++i) {
      const std::uint64_t next = words_[i] & other[i];
      changed |= next != words_[i];
      words_[i] = next;
    }
    return changed;
  }
  bool intersect_with(const Bitset& other) { return intersect_with(other.words()); }
  void unite_with(const Bitset& other) {
    for (std::size_t i = 0; i < words_.size(); ++i) words_[i] |= other.words_[i];
  }

  [[nodiscard]] std::span<const std::uint64_t> words() const { return words_; }
  [[nodiscard]] std::span<std::uint64_t> words() { return words_; }

  friend bool operator==(const Bitset&, const Bitset&) = default;

 private:
  int size_{0};                       // number of bits
  std::vector<std::uint64_t> words_;  // words_for(size_) words; bits >= size_ are zero
};

// Rows × columns bits, row-major, each row padded to whole words (so a row is a word span that
// intersects a Bitset of `columns` bits). Same zero-padding invariant as Bitset.
class BitMatrix {
 public:
  BitMatrix() = default;
  BitMatrix(int rows, int columns)
      : rows_{rows},
        columns_{columns},
        row_words_{words_for(columns)},
        words_(static_cast<std::size_t>(rows) * static_cast<std::size_t>(words_for(columns)), 0) {}

  [[nodiscard]] int rows() const { return rows_; }
  [[nodiscard]] int columns() const { return columns_; }
  [[nodiscard]] std::span<const std::uint64_t> row(int r) const {
    return {words_.data() + offset(r), static_cast<std::size_t>(row_words_)};
  }
  [[nodiscard]] std::span<std::uint64_t> row(int r) {
    return {words_.data() + offset(r), static_cast<std::size_t>(row_words_)};
  }
  [[nodiscard]] bool test(int r, int c) const {
    return ((row(r)[static_cast<std::size_t>(c / kWordBits)] >> (c % kWordBits)) & 1U) != 0;
  }
  void set(int r, int c) {
    row(r)[static_cast<std::size_t>(c / kWordBits)] |= std::uint64_t{1} << (c % kWordBits);
  }
  void reset(int r, int c) {
    row(r)[static_cast<std::size_t>(c / kWordBits)] &= ~(std::uint64_t{1} << (c % kWordBits));
  }
  // Adds zero rows and columns (never shrinks); re-lays the words out when a row needs more.
  void grow(int rows, int columns) {
    if (words_for(columns) != row_words_) {
      BitMatrix wider(rows, columns);
      for (int r = 0; r < rows_; ++r) {
        const auto from = row(r);
        std::copy(from.begin(), from.end(), wider.row(r).begin());
      }
      *this = std::move(wider);
      return;
    }
    rows_ = rows;
    columns_ = columns;
    words_.resize(static_cast<std::size_t>(rows) * static_cast<std::size_t>(row_words_), 0);
  }
  // this &= other (same shape).
  void intersect_with(const BitMatrix& other) {
    for (std::size_t i = 0; i < words_.size(); ++i) words_[i] &= other.words_[i];
  }
  // Column-for-row copy.
  [[nodiscard]] BitMatrix transposed() const {
    BitMatrix result(columns_, rows_);
    for (int r = 0; r < rows_; ++r) {
      for (int c = span_find_next(row(r), columns_, 0); c >= 0;
           c = span_find_next(row(r), columns_, c + 1)) {
        result.set(c, r);
      }
    }
    return result;
  }

  friend bool operator==(const BitMatrix&, const BitMatrix&) = default;

 private:
  [[nodiscard]] std::size_t offset(int r) const {
    return static_cast<std::size_t>(r) * static_cast<std::size_t>(row_words_);
  }

  int rows_{0};
  int columns_{0};
  int row_words_{0};                  // words_for(columns_)
  std::vector<std::uint64_t> words_;  // rows_ * row_words_ words; padding bits zero
};

}  // namespace spar::planner::cms::internal
