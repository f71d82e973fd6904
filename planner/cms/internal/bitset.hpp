// Bit sets and bit matrices as 64-bit words, for the CMS's label sets, allowed-pair matrices and
// the ordering graph's transitive closure: Bitset (one set, owning), BitMatrix (rows of bits,
// owning), BitsetArray (many sets in one flat vector, so copying them all is one memcpy) and
// BitsRef (a view of one set in a BitsetArray). All plain values.
//
// Invariant of all four: bits at positions >= the set's size (or a row's width) are zero, so
// word-wise comparisons, counts and intersection tests never see stray bits. Private to
// planner/cms/.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
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

[[nodiscard]] inline bool span_none(std::span<const std::uint64_t> words) {
  return std::all_of(words.begin(), words.end(), [](std::uint64_t word) { return word == 0; });
}

// destination &= source (spans of equal length); returns true if destination changed.
inline bool span_intersect_with(std::span<std::uint64_t> destination,
                                std::span<const std::uint64_t> source) {
  bool changed = false;
  for (std::size_t i = 0; i < destination.size(); ++i) {
    const std::uint64_t next = destination[i] & source[i];
    changed |= next != destination[i];
    destination[i] = next;
  }
  return changed;
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
  [[nodiscard]] bool test(int bit) const { return span_test(words_, bit); }
  void set(int bit) {
    words_[static_cast<std::size_t>(bit / kWordBits)] |= std::uint64_t{1} << (bit % kWordBits);
  }
  void reset(int bit) {
    words_[static_cast<std::size_t>(bit / kWordBits)] &= ~(std::uint64_t{1} << (bit % kWordBits));
  }

  [[nodiscard]] bool none() const { return span_none(words_); }
  // Smallest member >= from, or -1.
  [[nodiscard]] int find_next(int from) const { return span_find_next(words_, size_, from); }
  [[nodiscard]] int find_first() const { return find_next(0); }

  // this &= other (a row of the same width); returns true if this changed.
  bool intersect_with(std::span<const std::uint64_t> other) {
    return span_intersect_with(words_, other);
  }
  [[nodiscard]] std::span<const std::uint64_t> words() const { return words_; }

  friend bool operator==(const Bitset&, const Bitset&) = default;

 private:
  int size_{0};                       // number of bits
  std::vector<std::uint64_t> words_;  // words_for(size_) words; bits >= size_ are zero
};

// A view of `size` bits stored in words_for(size) words it does not own (a set of a BitsetArray,
// or a Bitset); valid while that storage is neither resized nor destroyed. `Word` is
// std::uint64_t (mutable view) or const std::uint64_t.
template <class Word>
class BasicBitsRef {
 public:
  BasicBitsRef(Word* words, int size) : words_{words}, size_{size} {}
  // A const view of a mutable one, and of a Bitset.
  template <class Other>
  BasicBitsRef(const BasicBitsRef<Other>& other)  // NOLINT: implicit, like span's
      : words_{other.words().data()}, size_{other.size()} {}
  BasicBitsRef(const Bitset& set)  // NOLINT: implicit, like span's
      requires std::is_const_v<Word>
      : words_{set.words().data()}, size_{set.size()} {}

  [[nodiscard]] int size() const { return size_; }
  [[nodiscard]] std::span<Word> words() const {
    return {words_, static_cast<std::size_t>(words_for(size_))};
  }
  [[nodiscard]] bool test(int bit) const { return span_test(words(), bit); }
  [[nodiscard]] bool none() const { return span_none(words()); }
  [[nodiscard]] int count() const {
    int total = 0;
    for (const std::uint64_t word : words()) total += std::popcount(word);
    return total;
  }
  [[nodiscard]] int find_next(int from) const { return span_find_next(words(), size_, from); }
  [[nodiscard]] int find_first() const { return find_next(0); }
  [[nodiscard]] bool intersects(std::span<const std::uint64_t> other) const {
    return spans_intersect(words(), other);
  }
  [[nodiscard]] bool equals(BasicBitsRef<const std::uint64_t> other) const {
    return size_ == other.size() &&
           std::equal(words().begin(), words().end(), other.words().begin());
  }
  [[nodiscard]] Bitset copy() const { return Bitset(size_, words()); }

  void set(int bit) const requires(!std::is_const_v<Word>) {
    words_[static_cast<std::size_t>(bit / kWordBits)] |= std::uint64_t{1} << (bit % kWordBits);
  }
  void reset(int bit) const requires(!std::is_const_v<Word>) {
    words_[static_cast<std::size_t>(bit / kWordBits)] &= ~(std::uint64_t{1} << (bit % kWordBits));
  }
  // this &= other (words of the same width); returns true if this changed.
  bool intersect_with(std::span<const std::uint64_t> other) const requires(!std::is_const_v<Word>) {
    return span_intersect_with(words(), other);
  }
  void assign(BasicBitsRef<const std::uint64_t> other) const requires(!std::is_const_v<Word>) {
    std::copy(other.words().begin(), other.words().end(), words_);
  }
  void clear() const requires(!std::is_const_v<Word>) {
    std::fill(words().begin(), words().end(), 0);
  }

 private:
  Word* words_;
  int size_;
};
using BitsRef = BasicBitsRef<std::uint64_t>;
using ConstBitsRef = BasicBitsRef<const std::uint64_t>;

// Many bit sets of fixed sizes in one flat vector of words: copying the array is one memcpy.
class BitsetArray {
 public:
  // Appends an empty set of `size` bits; returns its index.
  int add(int size) {
    offsets_.push_back(words_.size());
    sizes_.push_back(size);
    words_.resize(words_.size() + static_cast<std::size_t>(words_for(size)), 0);
    return static_cast<int>(sizes_.size()) - 1;
  }
  [[nodiscard]] int count() const { return static_cast<int>(sizes_.size()); }
  [[nodiscard]] BitsRef operator[](int index) {
    return {words_.data() + offsets_[static_cast<std::size_t>(index)],
            sizes_[static_cast<std::size_t>(index)]};
  }
  [[nodiscard]] ConstBitsRef operator[](int index) const {
    return {words_.data() + offsets_[static_cast<std::size_t>(index)],
            sizes_[static_cast<std::size_t>(index)]};
  }

  friend bool operator==(const BitsetArray&, const BitsetArray&) = default;

 private:
  std::vector<std::uint64_t> words_;  // the sets one after the other
  std::vector<std::size_t> offsets_;  // where each set's words start
  std::vector<int> sizes_;            // each set's size in bits
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
  // All rows, one after the other.
  [[nodiscard]] std::span<const std::uint64_t> words() const { return words_; }
  [[nodiscard]] std::span<const std::uint64_t> row(int r) const {
    return {words_.data() + offset(r), static_cast<std::size_t>(row_words_)};
  }
  [[nodiscard]] std::span<std::uint64_t> row(int r) {
    return {words_.data() + offset(r), static_cast<std::size_t>(row_words_)};
  }
  [[nodiscard]] bool test(int r, int c) const { return span_test(row(r), c); }
  void set(int r, int c) {
    row(r)[static_cast<std::size_t>(c / kWordBits)] |= std::uint64_t{1} << (c % kWordBits);
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
  // Column-for-row copy, 64 x 64 blocks at a time.
  [[nodiscard]] BitMatrix transposed() const {
    BitMatrix result(columns_, rows_);
    std::uint64_t block[kWordBits];
    for (int row_block = 0; row_block < words_for(rows_); ++row_block) {
      for (int column_block = 0; column_block < row_words_; ++column_block) {
        for (int i = 0; i < kWordBits; ++i) {
          const int r = row_block * kWordBits + i;
          block[i] = r < rows_ ? row(r)[static_cast<std::size_t>(column_block)] : 0;
        }
        transpose_block(block);
        for (int i = 0; i < kWordBits; ++i) {
          const int c = column_block * kWordBits + i;
          if (c < columns_) result.row(c)[static_cast<std::size_t>(row_block)] = block[i];
        }
      }
    }
    return result;
  }

  friend bool operator==(const BitMatrix&, const BitMatrix&) = default;

 private:
  // Transposes a 64 x 64 bit block in place (bit j of block[i] <-> bit i of block[j]) by
  // swapping ever smaller off-diagonal sub-blocks (Hacker's Delight, section 7-3).
  static void transpose_block(std::uint64_t (&block)[kWordBits]) {
    std::uint64_t low_half = 0x00000000FFFFFFFFULL;  // columns whose bit `width` is clear
    for (int width = 32; width != 0; width >>= 1, low_half ^= low_half << width) {
      for (int k = 0; k < kWordBits; k = ((k | width) + 1) & ~width) {
        const std::uint64_t swapped = ((block[k] >> width) ^ block[k | width]) & low_half;
        block[k | width] ^= swapped;
        block[k] ^= swapped << width;
      }
    }
  }
  [[nodiscard]] std::size_t offset(int r) const {
    return static_cast<std::size_t>(r) * static_cast<std::size_t>(row_words_);
  }

  int rows_{0};
  int columns_{0};
  int row_words_{0};                  // words_for(columns_)
  std::vector<std::uint64_t> words_;  // rows_ * row_words_ words; padding bits zero
};

}  // namespace spar::planner::cms::internal
