#include "spar/symbolic/expr.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <iterator>
#include <limits>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace spar::symbolic {
namespace {

constexpr std::uint32_t kEmptySlot = 0xFFFFFFFFu;
// Integers in [-kSmallInteger, kSmallInteger] find their index in a pool's numbers without hashing.
constexpr std::int64_t kSmallInteger = 16;

// kFlattenLimit (expr.hpp): a sum or product with more operands stays one opaque operand of its
// parent. Without the cap, building a deep chain one operation at a time (or
// differentiating one: d sin(u) = cos(u)·du nests products n deep) copies O(n) operands per
// step, O(n²) in all. Below the cap, canonical forms are exactly as documented in expr.hpp.
// The cap is also the cost of a step: a sum grown one term at a time (a chain's translation
// entries) copies about cap/2 operands per step. At 64 that copying was half of a deep chain's
// memory and the reason a 48-transform chain cost more per transform than a 24-transform one
// (bench/RESULTS.md, issue 13); at 16 neither is true, and no test or benchmark bound widened.

std::size_t mix(std::size_t h, std::size_t v) {
  return (h ^ (v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2))) * 0xBF58476D1CE4E5B9ull;
}

bool is_identifier_start(unsigned char c) { return c < 0x80 && (std::isalpha(c) || c == '_'); }
bool is_identifier_char(unsigned char c) { return c < 0x80 && (std::isalnum(c) || c == '_'); }

// Exact square root of a non-negative 64-bit integer, if it is a perfect square.
std::optional<std::int64_t> exact_isqrt(std::int64_t v) {
  if (v < 0) return std::nullopt;
  auto r = static_cast<std::int64_t>(std::sqrt(static_cast<double>(v)));
  while (r > 0 && static_cast<__int128>(r) * r > v) --r;
  while (static_cast<__int128>(r + 1) * (r + 1) <= v) ++r;
  if (static_cast<__int128>(r) * r != v) return std::nullopt;
  return r;
}

}  // namespace

std::string_view function_name(Op op) {
  switch (op) {
#define SPAR_NAME(Name, name, ...) \
  case Op::k##Name:                \
    return #name;
    SPAR_UNARY_FUNCTIONS(SPAR_NAME)
    SPAR_BINARY_FUNCTIONS(SPAR_NAME)
#undef SPAR_NAME
    default:
      return "";
  }
}

bool is_unary_function(Op op) {
  switch (op) {
#define SPAR_CASE(Name, ...) case Op::k##Name:
    SPAR_UNARY_FUNCTIONS(SPAR_CASE)
    return true;
#undef SPAR_CASE
    default:
      return false;
  }
}

bool is_binary_function(Op op) {
  switch (op) {
#define SPAR_CASE(Name, ...) case Op::k##Name:
    SPAR_BINARY_FUNCTIONS(SPAR_CASE)
    return true;
#undef SPAR_CASE
    default:
      return false;
  }
}

// Memory for a large array (a big pool's nodes, operands and hash slots): 2 MiB aligned and, on
// Linux, marked for transparent huge pages, so that touching it takes one page fault per 2 MiB
// instead of per 4 KiB and random probes miss the TLB less. Small blocks come from malloc. Free
// either with std::free.
constexpr std::size_t kHugePage = std::size_t{2} << 20;
void* allocate_block(std::size_t bytes) {
  void* block = nullptr;
  if (bytes >= kHugePage) {
    block = std::aligned_alloc(kHugePage, (bytes + kHugePage - 1) / kHugePage * kHugePage);
#ifdef __linux__
    if (block != nullptr) madvise(block, bytes, MADV_HUGEPAGE);  // advice only: may be ignored
#endif
  } else {
    block = std::malloc(bytes);
  }
  if (block == nullptr) throw std::bad_alloc();
  return block;
}

// std::allocator through allocate_block.
template <class T>
struct BlockAllocator {
  using value_type = T;
  BlockAllocator() = default;
  template <class U>
  BlockAllocator(const BlockAllocator<U>&) {}  // NOLINT: converting, as allocators are
  T* allocate(std::size_t n) { return static_cast<T*>(allocate_block(n * sizeof(T))); }
  void deallocate(T* p, std::size_t) { std::free(p); }
  friend bool operator==(const BlockAllocator&, const BlockAllocator&) { return true; }
};

// Address space for a large array: a range reserved once (no memory committed until written) that
// the array then grows in place, so that growing copies nothing and the kernel zeroes each page
// once, when first written. On Linux; returns nullptr elsewhere or when refused (a strict
// overcommit policy, a small RLIMIT_AS), and the array keeps growing by copying.
constexpr std::size_t kReservation = std::size_t{1} << 34;  // 16 GiB per array, moved if outgrown
void* reserve_range(std::size_t bytes) {
#ifdef __linux__
  void* range = mmap(nullptr, bytes, PROT_READ | PROT_WRITE,
                     MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (range == MAP_FAILED) return nullptr;
  madvise(range, bytes, MADV_HUGEPAGE);  // advice only: may be ignored
  return range;
#else
  (void)bytes;
  return nullptr;
#endif
}

// The arena's node, operand and factor arrays: a growable array of trivially copyable elements,
// indexed with one load (no chunk arithmetic). A fresh pool's arrays allocate on first use and
// grow by realloc; from 2 MiB on an array moves once into a reserved range (reserve_range) and
// grows there without copying. Growing may move the elements, so element addresses are not
// stable: hold ids, never a Node& across a call that may build a node.
template <class T>
class PodVector {
  static_assert(std::is_trivially_copyable_v<T>);

 public:
  PodVector() = default;
  PodVector(const PodVector&) = delete;
  PodVector& operator=(const PodVector&) = delete;
  ~PodVector() {
#ifdef __linux__
    if (reserved_ != 0) {
      munmap(data_, reserved_);
      return;
    }
#endif
    std::free(data_);
  }

  [[nodiscard]] std::size_t size() const { return size_; }
  T& operator[](std::size_t i) { return data_[i]; }
  const T& operator[](std::size_t i) const { return data_[i]; }
  [[nodiscard]] const T* data() const { return data_; }
  void push_back(T value) {  // by value: an element of this array stays valid across grow()
    if (size_ == capacity_) grow();
    data_[size_++] = value;
  }
  void shrink_to(std::size_t size) { size_ = size; }  // size <= size()
  // Emptied with its memory kept when that is malloc'd and at most `bytes` (a spare, see
  // SpareArrays).
  [[nodiscard]] bool empty_as_spare(std::size_t bytes) {
    if (reserved_ != 0 || capacity_ * sizeof(T) > bytes) return false;
    size_ = 0;
    return true;
  }
  void swap(PodVector& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    std::swap(capacity_, other.capacity_);
    std::swap(reserved_, other.reserved_);
  }

 private:
  [[gnu::noinline]] void grow() {  // out of line, so that push_back inlines
    const std::size_t capacity = capacity_ == 0 ? 16 : capacity_ * 2;
    const std::size_t bytes = capacity * sizeof(T);
    if (reserved_ != 0) {
#ifdef __linux__
      if (bytes > reserved_) {  // outgrown: move the range (page tables move, no copy)
        void* moved = mremap(data_, reserved_, reserved_ * 2, MREMAP_MAYMOVE);
        if (moved == MAP_FAILED) throw std::bad_alloc();
        data_ = static_cast<T*>(moved);
        reserved_ *= 2;
      }
#endif
    } else if (void* range = bytes >= kHugePage ? reserve_range(kReservation) : nullptr) {
      if (size_ != 0) std::memcpy(range, static_cast<const void*>(data_), size_ * sizeof(T));
      std::free(data_);
      data_ = static_cast<T*>(range);
      reserved_ = kReservation;
    } else {
      void* data = std::realloc(static_cast<void*>(data_), bytes);
      if (data == nullptr) throw std::bad_alloc();
      data_ = static_cast<T*>(data);
    }
    capacity_ = capacity;
  }
  T* data_{nullptr};
  std::size_t size_{0}, capacity_{0};
  std::size_t reserved_{0};  // bytes of the reserved range data_ starts, 0 if data_ is malloc's
};

// The pool's numbers: a vector whose elements never move. Chunk k holds kFirst·2^k elements, so
// element i lives in chunk bit_width(i / kFirst + 1) - 1; growing allocates a new chunk instead
// of copying, so references to its Numbers (Expr::constant(), Expr::factor()) stay valid for the
// pool's whole life.
template <class T>
class StableVector {
 public:
  [[nodiscard]] std::size_t size() const { return size_; }
  T& operator[](std::size_t i) { return at(i); }
  const T& operator[](std::size_t i) const { return const_cast<StableVector*>(this)->at(i); }
  void push_back(T value) {
    if (size_ == capacity_) {
      chunks_[chunk_count_] = std::make_unique<T[]>(kFirst << chunk_count_);
      capacity_ += kFirst << chunk_count_++;
    }
    at(size_++) = std::move(value);
  }

 private:
  static constexpr std::size_t kFirst = 16;
  T& at(std::size_t i) {
    const std::size_t biased =
        i + kFirst;  // chunk k holds biased indices [kFirst·2^k, kFirst·2^(k+1))
    const int chunk = std::bit_width(biased) - 1 - std::countr_zero(kFirst);
    return chunks_[chunk][biased - (kFirst << chunk)];
  }
  std::unique_ptr<T[]> chunks_[32];  // kFirst·(2^32 - 1) elements in all: more than 32-bit ids
  std::size_t chunk_count_{0}, size_{0}, capacity_{0};
};

// Node layout. Invariants (checked by ExprPool::check_invariants):
//  * operands of node n are operand_ids[begin, begin + count) with parallel factor_ids (indices
//    into numbers); every operand id is smaller than n (the arena is topologically ordered:
//    children are built first);
//  * number and factor_ids index `numbers`, which holds each distinct Number (by ==) once, so
//    two nodes are structurally equal iff their ops, number indices, operand ids and factor
//    indices are equal;
//  * Constant: count == 0, number is the value. Variable: count == 0, begin is the index into
//    names. Add/Mul: the canonical forms of expr.hpp (operands sorted strictly by id, no zero
//    exponent; no zero coefficient except on a partial term, a domain guard). Functions and
//    Pow: factors are all one;
//  * partial: some real values of the variables are outside the node's domain (computed from
//    the op and the operands on construction: see partial_node());
//  * the node table holds every node id exactly once, under the 32-bit key of its node_hash();
//    the variable table every Variable node's id, under the key of its name; the number table
//    every index into numbers except the small integers', under the key of its Number::hash().
struct Node {  // 16 bytes
  std::uint32_t begin;
  std::uint32_t count;
  std::uint32_t number;  // index into numbers
  Op op;
  bool partial{false};
  bool has_parent{false};  // some node has this one as an operand
};

// A set of ids under 32-bit keys (hashes): open addressing with linear probing over a power-of-two
// number of slots, at most 3/4 full (a slot is 8 bytes: eight per cache line, so a longer probe
// costs little, and a large table touches less memory). A slot keeps its id's key, whose low bits
// place it and whose 32 bits filter a probe (a lookup in a large table reads one slot's cache line
// and, unless keys collide, only the id it is after), and growing re-places slots by their keys,
// reading nothing else. Invariant: every id is in the probe sequence that starts at its key's home
// slot.
class HashIndex {
 public:
  struct Slot {
    std::uint32_t id{kEmptySlot};
    std::uint32_t key{0};
  };
  explicit HashIndex(std::size_t slots = 0) : slots_(slots) {}
  [[nodiscard]] std::size_t slot_count() const { return slots_.size(); }
  [[nodiscard]] const Slot& slot(std::size_t s) const { return slots_[s]; }
  [[nodiscard]] std::size_t home(std::uint32_t key) const { return key & (slots_.size() - 1); }
  [[nodiscard]] std::size_t next(std::size_t s) const { return (s + 1) & (slots_.size() - 1); }
  void prefetch(std::uint32_t key) const {
    if (!slots_.empty()) __builtin_prefetch(&slots_[home(key)]);
  }
  // The id under `key` for which is(id) holds, or kEmptySlot.
  template <class Is>
  std::uint32_t find(std::uint32_t key, Is&& is) const {
    if (slots_.empty()) return kEmptySlot;
    for (std::size_t s = home(key); slots_[s].id != kEmptySlot; s = next(s)) {
      if (slots_[s].key == key && is(slots_[s].id)) return slots_[s].id;
    }
    return kEmptySlot;
  }
  // Emptied with its slots kept when at least 1/8 full and at most `bytes` (a spare, see
  // SpareArrays), so that emptying costs no more than filling did.
  [[nodiscard]] bool empty_as_spare(std::size_t bytes) {
    if (slots_.size() * sizeof(Slot) > bytes || count_ * 8 < slots_.size()) return false;
    std::fill(slots_.begin(), slots_.end(), Slot{});
    count_ = 0;
    return true;
  }
  void swap(HashIndex& other) noexcept {
    slots_.swap(other.slots_);
    std::swap(count_, other.count_);
  }
  // Adds `id` (not present) under `key`, then doubles the slots if more than 3/4 full.
  void insert(std::uint32_t id, std::uint32_t key) {
    if (slots_.empty()) slots_.resize(16);
    std::size_t s = home(key);
    while (slots_[s].id != kEmptySlot) s = next(s);
    slots_[s] = {id, key};
    if (++count_ * 4 > slots_.size() * 3) grow();
  }

 private:
  void grow() {
    if (slots_.size() >= (std::size_t{1} << 32)) return;  // 32-bit keys place no further
    auto old = std::exchange(slots_, std::vector<Slot, BlockAllocator<Slot>>(slots_.size() * 2));
    for (const Slot& slot : old) {
      if (slot.id == kEmptySlot) continue;
      std::size_t s = home(slot.key);
      while (slots_[s].id != kEmptySlot) s = next(s);
      slots_[s] = slot;
    }
  }
  std::vector<Slot, BlockAllocator<Slot>> slots_;
  std::size_t count_{0};
};

// A vector lent for one call's scratch from the thread's spares (sum() and product() nest, so
// several are out at once): once the spares are warm, building a node allocates nothing for its
// entries. It comes back emptied and is kept while at most kMaxLentBytes and while the thread
// keeps fewer than kMaxSpares (their list is reserved once, so giving back never allocates).
template <class T>
class LentVector {
 public:
  LentVector() {
    if (std::vector<std::vector<T>>* spares = thread_spares(); spares && !spares->empty()) {
      vector_ = std::move(spares->back());
      spares->pop_back();
    }
  }
  ~LentVector() {
    vector_.clear();
    if (std::vector<std::vector<T>>* spares = thread_spares();
        spares && spares->size() < kMaxSpares && vector_.capacity() * sizeof(T) <= kMaxLentBytes)
      spares->push_back(std::move(vector_));
  }
  LentVector(const LentVector&) = delete;
  LentVector& operator=(const LentVector&) = delete;
  std::vector<T>& operator*() { return vector_; }

 private:
  static constexpr std::size_t kMaxLentBytes = std::size_t{64} << 10;
  static constexpr std::size_t kMaxSpares = 32;
  // The thread's spares, or nullptr once they are destroyed (a vector returned at thread exit
  // is freed instead).
  static std::vector<std::vector<T>>* thread_spares() {
    thread_local bool gone = false;
    struct Spares {
      Spares() { vectors.reserve(kMaxSpares); }
      ~Spares() { gone = true; }
      std::vector<std::vector<T>> vectors;
    };
    thread_local Spares spares;
    return gone ? nullptr : &spares.vectors;
  }
  std::vector<T> vector_;
};

// The 32-bit key of a 64-bit hash (mix() leaves its best bits on top).
inline std::uint32_t key_of(std::size_t hash) { return static_cast<std::uint32_t>(hash >> 32); }

// The node, operand and factor arrays and the node table of a thread's last pool, emptied with
// their memory kept: the thread's next pool starts from them, so that building many fresh pools in
// a row (a planner's instances, a benchmark's repetitions) neither regrows their arrays nor faults
// their memory in again. Arrays over kMaxSpareBytes are freed instead: a thread keeps < 1 MiB.
struct SpareArrays {
  static constexpr std::size_t kMaxSpareBytes = std::size_t{256} << 10;
  PodVector<Node> nodes;
  PodVector<std::uint32_t> operand_ids, factor_ids;
  HashIndex table;
  bool full{false};  // holds a pool's arrays, not yet taken
  ~SpareArrays();
};
// Set once the thread's SpareArrays is destroyed (a pool that outlives it frees its own arrays).
thread_local bool spare_arrays_gone = false;
thread_local SpareArrays spare_arrays;
SpareArrays::~SpareArrays() { spare_arrays_gone = true; }

struct ExprPool::Impl {
  Impl() {
    if (spare_arrays_gone || !spare_arrays.full) return;
    nodes.swap(spare_arrays.nodes);
    operand_ids.swap(spare_arrays.operand_ids);
    factor_ids.swap(spare_arrays.factor_ids);
    if (spare_arrays.table.slot_count() != 0) table.swap(spare_arrays.table);
    spare_arrays.full = false;
  }
  ~Impl() {
    if (spare_arrays_gone || spare_arrays.full) return;
    constexpr std::size_t kMax = SpareArrays::kMaxSpareBytes;
    // What is not kept stays here, and the spare's previous (empty) arrays come back with it.
    if (nodes.empty_as_spare(kMax)) nodes.swap(spare_arrays.nodes);
    if (operand_ids.empty_as_spare(kMax)) operand_ids.swap(spare_arrays.operand_ids);
    if (factor_ids.empty_as_spare(kMax)) factor_ids.swap(spare_arrays.factor_ids);
    if (table.empty_as_spare(kMax)) table.swap(spare_arrays.table);
    spare_arrays.full = true;
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  PodVector<Node> nodes;
  PodVector<std::uint32_t> operand_ids;
  PodVector<std::uint32_t> factor_ids;  // indices into numbers, parallel to operand_ids
  StableVector<Number> numbers;         // each distinct Number once
  std::vector<std::string> names;
  HashIndex table;       // node ids, by node_hash()
  HashIndex variables;   // Variable node ids, by name_key()
  HashIndex number_ids;  // indices into numbers, by number_key(), except...
  std::uint32_t small_integers[2 * kSmallInteger + 1]{};  // ...-16..16: index + 1, or 0 if new
  // Traversal marks: node n is visited in the current traversal iff marks[n] == epoch.
  std::vector<std::uint32_t> marks;
  std::uint32_t epoch = 0;
  // topological_order's stack of (node, next operand to visit), kept for its capacity.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> traversal;

  // The index of `value` in numbers, adding it if new.
  std::uint32_t number_index(const Number& value) {
    if (is_small_integer(value)) return number_index_of_small(value.numerator());
    const std::uint32_t key = number_key(value);
    std::uint32_t index = find_number(value, key);
    if (index == kEmptySlot) {
      index = add_number(value);
      number_ids.insert(index, key);
    }
    return index;
  }
  static bool is_small_integer(const Number& value) {
    return value.is_integer() && value.numerator() >= -kSmallInteger &&
           value.numerator() <= kSmallInteger;
  }
  static std::uint32_t number_key(const Number& value) { return key_of(mix(0, value.hash())); }
  // The index of `value` (not a small integer) in numbers, or kEmptySlot.
  std::uint32_t find_number(const Number& value, std::uint32_t key) const {
    return number_ids.find(key, [&](std::uint32_t i) { return numbers[i] == value; });
  }
  std::uint32_t add_number(const Number& value) {
    numbers.push_back(value);
    return static_cast<std::uint32_t>(numbers.size() - 1);
  }
  std::uint32_t one_index() { return number_index_of_small(1); }
  std::uint32_t number_index_of_small(std::int64_t value) {
    std::uint32_t& known = small_integers[value + kSmallInteger];
    if (known == 0) known = add_number(Number::integer(value)) + 1;
    return known - 1;
  }
  static std::uint32_t name_key(std::string_view name) {
    return key_of(mix(0, std::hash<std::string_view>{}(name)));
  }
  // The Variable node named `name`, or kEmptySlot.
  std::uint32_t find_variable(std::string_view name, std::uint32_t key) const {
    return variables.find(key, [&](std::uint32_t id) { return names[nodes[id].begin] == name; });
  }
  const Number& number_of(const Node& node) const { return numbers[node.number]; }
  // Whether node `id` is the constant `value` (-16..16, which has one index in numbers).
  bool is_integer_constant(std::uint32_t id, std::int64_t value) const {
    const Node& node = nodes[id];
    return node.op == Op::kConstant && small_integers[value + kSmallInteger] == node.number + 1;
  }
  // A guard sum 0·t1 + ... : zero wherever it is defined.
  bool is_guard(std::uint32_t id) const {
    const Node& node = nodes[id];
    if (node.op != Op::kAdd || !number_of(node).is_zero()) return false;
    for (std::uint32_t i = node.begin; i < node.begin + node.count; ++i)
      if (!factor(i).is_zero()) return false;
    return true;
  }
  // The one form of a product undefined everywhere, G^-1 for a guard sum G (see product()).
  bool is_undefined_product(std::uint32_t id) const {
    const Node& node = nodes[id];
    return node.op == Op::kMul && node.count == 1 && number_of(node).is_one() &&
           factor(node.begin) == Number::integer(-1) && is_guard(operand_ids[node.begin]);
  }
  // An upper bound on the entries sum() (op Add) or product() (op Mul) collects from `terms`:
  // the operands of the sums or products it flattens (and of a product's guard sums, 0·t + ...),
  // one entry for every other term.
  std::size_t flattened_size(std::span<const Term> terms, Op op, const ExprPool* pool) const {
    std::size_t size = 0;
    for (const Term& term : terms) {
      std::size_t entries = 1;
      if (!term.expr.is_null() && &term.expr.pool() == pool) {
        const Node& node = nodes[term.expr.id()];
        if ((node.op == op && node.count <= kFlattenLimit) ||
            (op == Op::kMul && node.op == Op::kAdd && number_of(node).is_zero())) {
          entries = std::max<std::size_t>(node.count, 1);
        }
      }
      size += entries;
    }
    return size;
  }
  const Number& factor(std::size_t i) const { return numbers[factor_ids[i]]; }
  // Appends an operand of a node under construction.
  void push_operand(std::uint32_t id, std::uint32_t factor_index) {
    operand_ids.push_back(id);
    factor_ids.push_back(factor_index);
  }

  // The hash of node (op, number, operands [begin, begin + count) or var_index).
  std::size_t node_hash(Op op, std::uint32_t number, std::uint32_t begin, std::uint32_t count,
                        std::uint32_t var_index) const {
    std::size_t h = mix(static_cast<std::size_t>(op), number);
    if (op == Op::kVariable) h = mix(h, var_index);
    for (std::uint32_t i = begin; i < begin + count; ++i) {
      h = mix(h, (static_cast<std::size_t>(factor_ids[i]) << 32) | operand_ids[i]);
    }
    return h;
  }
  std::size_t node_hash(std::uint32_t id) const {
    const Node& n = nodes[id];
    return node_hash(n.op, n.number, n.begin, n.count, n.begin);
  }

  // Whether node `id` is (op, number, operands [begin, begin + count) or var_index).
  bool matches(std::uint32_t id, Op op, std::uint32_t number, std::uint32_t begin,
               std::uint32_t count, std::uint32_t var_index) const {
    const Node& x = nodes[id];
    if (x.op != op || x.count != count || x.number != number) return false;
    if (op == Op::kVariable) return x.begin == var_index;
    return std::equal(operand_ids.data() + x.begin, operand_ids.data() + x.begin + count,
                      operand_ids.data() + begin) &&
           std::equal(factor_ids.data() + x.begin, factor_ids.data() + x.begin + count,
                      factor_ids.data() + begin);
  }
  bool same_node(std::uint32_t a, std::uint32_t b) const {
    const Node& y = nodes[b];
    return matches(a, y.op, y.number, y.begin, y.count, y.begin);
  }

  // Returns the id of the node (op, number, operands...), creating it if no equal node exists.
  // `begin` marks where its operands were appended to operand_ids/factor_ids; a duplicate's
  // operands are popped again.
  std::uint32_t intern(Op op, std::uint32_t number, std::uint32_t begin, std::uint32_t var_index) {
    const auto count = static_cast<std::uint32_t>(operand_ids.size() - begin);
    const std::uint32_t key = key_of(node_hash(op, number, begin, count, var_index));
    table.prefetch(key);  // the one cache miss of a lookup in a large pool
    // A node with an operand that is no node's operand yet is new: no lookup. (Inserting it still
    // reads its slot, but nothing waits for that read.) In a growing chain most nodes are.
    bool fresh = false;
    for (std::uint32_t i = begin; i < begin + count && !fresh; ++i) {
      fresh = !nodes[operand_ids[i]].has_parent;
    }
    if (!fresh) {
      const std::uint32_t found = table.find(
          key, [&](std::uint32_t id) { return matches(id, op, number, begin, count, var_index); });
      if (found != kEmptySlot) {
        operand_ids.shrink_to(begin);
        factor_ids.shrink_to(begin);
        return found;
      }
    }
    if (nodes.size() >= 0xFFFFFFF0u) throw SymbolicError("expression pool is full (2^32 nodes)");
    const auto candidate = static_cast<std::uint32_t>(nodes.size());
    nodes.push_back(Node{op == Op::kVariable ? var_index : begin, count, number, op,
                         partial_node(op, begin, count)});
    for (std::uint32_t i = begin; i < begin + count; ++i) nodes[operand_ids[i]].has_parent = true;
    table.insert(candidate, key);
    return candidate;
  }

  // Whether a node (op over operands [begin, begin + count)) may be undefined for some real values
  // of its variables: log, sqrt, tan, asin, acos, atan2 and real powers are partial; so is a
  // product with a negative or fractional exponent of a non-constant base (x^-1 needs x != 0,
  // x^(1/2) needs x >= 0) or a fractional power of a constant that is not positive; and any
  // node with a partial operand.
  bool partial_node(Op op, std::uint32_t begin, std::uint32_t count) const {
    switch (op) {
      case Op::kConstant:
      case Op::kVariable:
        return false;
      case Op::kLog:
      case Op::kSqrt:
      case Op::kTan:
      case Op::kAsin:
      case Op::kAcos:
      case Op::kAtan2:
      case Op::kPow:
        return true;
      default:
        break;
    }
    for (std::uint32_t i = begin; i < begin + count; ++i) {
      const Node& operand = nodes[operand_ids[i]];
      if (operand.partial) return true;
      if (op != Op::kMul) continue;
      const Number& exponent = factor(i);
      if (operand.op == Op::kConstant) {
        if (!exponent.is_integer() && number_of(operand).sign() <= 0) return true;
      } else if (exponent.is_negative() || !exponent.is_integer()) {
        return true;
      }
    }
    return false;
  }

  std::uint32_t intern_leaf(Op op, std::uint32_t number, std::uint32_t var_index = 0) {
    return intern(op, number, static_cast<std::uint32_t>(operand_ids.size()), var_index);
  }
};

// ---------------------------------------------------------------------------------------------
// Expr accessors

Op Expr::op() const { return pool_->impl_->nodes[id_].op; }
const Number& Expr::constant() const { return pool_->impl_->number_of(pool_->impl_->nodes[id_]); }
const std::string& Expr::name() const {
  const Node& n = pool_->impl_->nodes[id_];
  if (n.op != Op::kVariable) throw std::logic_error("Expr::name() of a non-variable");
  return pool_->impl_->names[n.begin];
}
std::size_t Expr::operand_count() const { return pool_->impl_->nodes[id_].count; }
Expr Expr::operand(std::size_t i) const {
  return Expr(pool_, pool_->impl_->operand_ids[pool_->impl_->nodes[id_].begin + i]);
}
bool Expr::is_partial() const { return pool_->impl_->nodes[id_].partial; }
const Number& Expr::factor(std::size_t i) const {
  return pool_->impl_->factor(pool_->impl_->nodes[id_].begin + i);
}

// ---------------------------------------------------------------------------------------------
// ExprPool

ExprPool::ExprPool() : impl_(std::make_unique<Impl>()) {}
ExprPool::~ExprPool() = default;

std::size_t ExprPool::size() const { return impl_->nodes.size(); }

Expr ExprPool::constant(const Number& value) {
  return Expr(this, impl_->intern_leaf(Op::kConstant, impl_->number_index(value)));
}

Expr ExprPool::variable(std::string_view name) {
  if (name.empty() || !is_identifier_start(static_cast<unsigned char>(name[0])) ||
      !std::all_of(name.begin(), name.end(),
                   [](char c) { return is_identifier_char(static_cast<unsigned char>(c)); })) {
    const bool ascii = std::all_of(name.begin(), name.end(),
                                   [](char c) { return static_cast<unsigned char>(c) < 0x80; });
    throw SymbolicError("invalid variable name '" + std::string(name) +
                        "': use a letter or '_' followed by letters, digits or '_'" +
                        (ascii ? "" : std::string("; ") + kAsciiHint));
  }
  Impl& m = *impl_;
  const std::uint32_t key = Impl::name_key(name);
  std::uint32_t id = m.find_variable(name, key);
  if (id != kEmptySlot) return Expr(this, id);
  const auto index = static_cast<std::uint32_t>(m.names.size());
  m.names.emplace_back(name);
  id = m.intern_leaf(Op::kVariable, m.number_index_of_small(0), index);
  m.variables.insert(id, key);
  return Expr(this, id);
}

std::vector<Expr> ExprPool::variables() const {
  std::vector<Expr> result;
  for (std::uint32_t id = 0; id < impl_->nodes.size(); ++id) {
    if (impl_->nodes[id].op == Op::kVariable) {
      result.push_back(Expr(const_cast<ExprPool*>(this), id));
    }
  }
  std::sort(result.begin(), result.end(), [this](Expr a, Expr b) {
    return impl_->nodes[a.id()].begin < impl_->nodes[b.id()].begin;
  });
  return result;
}

namespace {

using Entry = std::pair<std::uint32_t, Number>;

// Sorts entries by id and merges equal ids by adding their numbers; drops zero numbers unless
// keep_zero(id) (a sum's partial term stays, with coefficient 0, as a domain guard). Reals are
// never added: an entry whose number is real (a fold that overflowed 64 bits, rounded once), or a
// total that overflows, moves to `spilled` as an entry of its own, and that id's total starts
// again from zero, so no real is rounded twice.
template <class KeepZero>
void sort_and_merge(std::vector<Entry>& entries, std::vector<Entry>& spilled, KeepZero keep_zero) {
  // Entries are often a few sorted runs (the operands of flattened sums or products, each
  // canonical): one or two runs are merged in linear time.
  const auto by_id = [](const Entry& a, const Entry& b) { return a.first < b.first; };
  const auto first_run = std::is_sorted_until(entries.begin(), entries.end(), by_id);
  if (first_run != entries.end()) {
    if (std::is_sorted(first_run, entries.end(), by_id)) {
      LentVector<Entry> merged;
      std::merge(entries.begin(), first_run, first_run, entries.end(), std::back_inserter(*merged),
                 by_id);
      entries.swap(*merged);
    } else {
      std::sort(entries.begin(), entries.end(), by_id);
    }
  }
  std::size_t out = 0;
  for (std::size_t i = 0; i < entries.size();) {
    // A lone rational entry is its own total (the loop below would add it to zero).
    if ((i + 1 == entries.size() || entries[i + 1].first != entries[i].first) &&
        entries[i].second.is_rational()) {
      if (!entries[i].second.is_zero() || keep_zero(entries[i].first)) {
        if (out != i) entries[out] = std::move(entries[i]);
        ++out;
      }
      ++i;
      continue;
    }
    Number total;
    bool any = false;
    std::size_t j = i;
    for (; j < entries.size() && entries[j].first == entries[i].first; ++j) {
      if (!entries[j].second.is_rational()) {
        spilled.push_back(entries[j]);
        continue;
      }
      Number next = total + entries[j].second;
      if (next.is_rational()) {
        total = std::move(next);
        any = true;
      } else {
        spilled.emplace_back(entries[i].first, std::move(next));
        total = Number();
        any = false;
      }
    }
    if (any && (!total.is_zero() || keep_zero(entries[i].first))) {
      entries[out++] = {entries[i].first, total};
    }
    i = j;
  }
  entries.resize(out);
}
void sort_and_merge(std::vector<Entry>& entries, std::vector<Entry>& spilled) {
  sort_and_merge(entries, spilled, [](std::uint32_t) { return false; });
}

}  // namespace

std::vector<Term> ExprPool::terms_of(std::span<const std::pair<std::uint32_t, Number>> entries) {
  std::vector<Term> terms;
  terms.reserve(entries.size());
  for (const auto& [id, factor] : entries) terms.push_back({Expr(this, id), factor});
  return terms;
}

// What SumForm and ProductForm share: the pool, the entries (node id, factor) of the node under
// construction, the reals that overflowed while folding, and the node built from the entries.
class ExprPool::CanonicalForm {
 protected:
  explicit CanonicalForm(ExprPool& pool) : pool_(pool), impl_(*pool.impl_) {}

  // The node op(number; entries), interned.
  Expr entries_node(Op op, const Number& number) {
    const auto begin = static_cast<std::uint32_t>(impl_.operand_ids.size());
    for (const Entry& e : entries_) impl_.push_operand(e.first, impl_.number_index(e.second));
    return Expr(&pool_, impl_.intern(op, impl_.number_index(number), begin, 0));
  }

  ExprPool& pool_;
  Impl& impl_;
  std::vector<Number> overflowed_;
  LentVector<Entry> lent_entries_;
  std::vector<Entry>& entries_{*lent_entries_};
};

// sum()'s rules (the header's canonical sum), one step each: collect the terms (folding rational
// constants into c0, flattening sums, moving a product's coefficient into its term's factor),
// merge equal terms, and build the node, or build again where something overflowed.
class ExprPool::SumForm : CanonicalForm {
 public:
  SumForm(ExprPool& pool, const Number& constant) : CanonicalForm(pool), c0_(constant) {}

  // Inlined (as the collect steps) into sum(): each is called from one place on the hottest path
  // of phase 2, where GCC would otherwise keep them calls (1.4% more instructions, measured).
  [[gnu::always_inline]] Expr build(std::span<const Term> terms) {
    entries_.reserve(impl_.flattened_size(terms, Op::kAdd, &pool_));
    for (const Term& term : terms) collect(term);
    // 0·t stays where t may be undefined: log(x) - log(x) is 0·log(x), undefined for x <= 0.
    std::vector<Entry> spilled;
    sort_and_merge(entries_, spilled, [&](std::uint32_t id) { return impl_.nodes[id].partial; });
    // k·U is U for a product U undefined everywhere (product() gives U for k·U): its factor is 1.
    if (may_hold_undefined_) {
      for (Entry& entry : entries_) {
        if (impl_.is_undefined_product(entry.first)) entry.second = Number::integer(1);
      }
    }
    if (!overflowed_.empty() || !spilled.empty()) return rebuilt(spilled);
    return node();
  }

 private:
  // c0 + addend; a fold that overflows 64 bits is a real rounded once (within one ulp), which is
  // folded no further but becomes a term (and c0 starts again from 0).
  void fold(const Number& addend) {
    const Number folded = addend.is_rational() ? c0_ + addend : addend;
    if (folded.is_rational()) {
      c0_ = folded;
    } else {
      overflowed_.push_back(folded);
      if (addend.is_rational()) c0_ = Number();
    }
  }

  // One term factor·expr into c0 or the entries.
  [[gnu::always_inline]] void collect(const Term& original) {
    if (original.expr.pool_ != &pool_)
      throw SymbolicError("expressions from different pools mixed");
    if (original.factor.is_zero() && !impl_.nodes[original.expr.id_].partial) return;
    Term term = original;
    if (!term.factor.is_rational()) {
      const Term unit[] = {{term.expr, Number::integer(1)}};
      term = {pool_.product(term.factor, unit), Number::integer(1)};
    }
    const Node& node = impl_.nodes[term.expr.id_];
    may_hold_undefined_ = may_hold_undefined_ || node.partial;
    switch (node.op) {
      case Op::kConstant:
        if (!impl_.number_of(node).is_rational()) {
          entries_.emplace_back(term.expr.id_, term.factor);
          break;
        }
        fold(term.factor * impl_.number_of(node));
        break;
      case Op::kAdd:
        if (node.count > kFlattenLimit) {
          entries_.emplace_back(term.expr.id_, term.factor);
          break;
        }
        fold(term.factor * impl_.number_of(node));
        for (std::uint32_t i = node.begin; i < node.begin + node.count; ++i) {
          const Number& factor = impl_.factor(i);
          entries_.emplace_back(impl_.operand_ids[i],
                                term.factor.is_one() ? factor : term.factor * factor);
        }
        break;
      case Op::kMul:
        if (!impl_.number_of(node).is_one()) {
          // c·Π b^e as a term: the coefficient moves into the term's factor.
          const Number coefficient = impl_.number_of(node);
          std::vector<Term> bases;
          bases.reserve(node.count);
          for (std::uint32_t i = node.begin; i < node.begin + node.count; ++i) {
            bases.push_back({Expr(&pool_, impl_.operand_ids[i]), impl_.factor(i)});
          }
          const Expr unit = pool_.product(Number::integer(1), bases);
          entries_.emplace_back(unit.id_, term.factor * coefficient);
          break;
        }
        [[fallthrough]];
      default:
        entries_.emplace_back(term.expr.id_, term.factor);
    }
  }

  // Overflowed constants and coefficients: build again, so that sum()'s entry turns each real
  // into an operand (Add factors stay rational).
  Expr rebuilt(const std::vector<Entry>& spilled) {
    std::vector<Term> all = pool_.terms_of(entries_);
    for (const Number& real : overflowed_) {  // |real| with its sign as the coefficient
      const bool negative = std::signbit(real.value());
      all.push_back({pool_.constant(negative ? -real : real), Number::integer(negative ? -1 : 1)});
    }
    for (const Entry& entry : spilled) all.push_back({Expr(&pool_, entry.first), entry.second});
    return pool_.sum(c0_, all);
  }

  // c0 + Σ factor·term as its node: a constant, a lone (scaled) term, or an Add.
  Expr node() {
    if (entries_.empty()) return pool_.constant(c0_);
    if (c0_.is_zero() && entries_.size() == 1 && !entries_[0].second.is_zero()) {
      const Expr only(&pool_, entries_[0].first);
      if (entries_[0].second.is_one()) return only;
      const Term scaled[] = {{only, Number::integer(1)}};
      return pool_.product(entries_[0].second, scaled);
    }
    return entries_node(Op::kAdd, c0_);
  }

  Number c0_;
  bool may_hold_undefined_{false};  // U is a partial product, and a sum holding one is partial
};

Expr ExprPool::sum(const Number& constant, std::span<const Term> terms) {
  // Real (inexact) numbers are never folded: a real constant term or coefficient stays a
  // Constant operand, so construction never rounds; the bounds engine encloses it instead.
  // A real becomes |c| with coefficient +-1, the form the parser gives "-c".
  if (!constant.is_rational()) {
    const bool negative = std::signbit(constant.value());
    std::vector<Term> all(terms.begin(), terms.end());
    all.push_back(
        {this->constant(negative ? -constant : constant), Number::integer(negative ? -1 : 1)});
    return sum(Number(), all);
  }
  return SumForm(*this, constant).build(terms);
}

namespace {

// Domain conditions of a power b^e: b != 0 when e < 0, b >= 0 when e is not an integer.
constexpr int kNonZero = 1, kNonNegative = 2;
int domain_of_exponent(const Number& e) {
  return (e.is_negative() ? kNonZero : 0) | (e.is_integer() ? 0 : kNonNegative);
}

}  // namespace

// product()'s rules (the header's canonical product), one step each: collect the factors
// (folding rational constants into the coefficient, flattening products, noting the domain each
// exponent required and the guards folding removes), then settle the undefined and zero
// products, merge equal bases, give a merged base back the domain condition it lost, fold the
// constant bases merging made integral, spill what overflowed, and build the node.
class ExprPool::ProductForm : CanonicalForm {
 public:
  ProductForm(ExprPool& pool, const Number& coefficient) : CanonicalForm(pool), c_(coefficient) {}

  [[gnu::always_inline]] Expr build(std::span<const Term> factors) {  // as SumForm::build
    const std::size_t flattened = impl_.flattened_size(factors, Op::kMul, &pool_);
    entries_.reserve(flattened);
    required_.reserve(flattened);
    for (const Term& factor : factors) collect(factor);
    if (undefined_) return undefined_product();
    if (c_.is_zero()) return zero();
    std::vector<Entry> spilled;
    sort_and_merge(entries_, spilled);
    // Flattening or merging may give a guard a positive integer power (G^(1/2)·G^(1/2)): zero.
    if (may_hold_guard_ && std::ranges::any_of(entries_, [&](const Entry& entry) {
          return positive_integer(entry.second) && impl_.is_guard(entry.first);
        })) {
      return zero();
    }
    guard_lost_domains();
    fold_constant_bases();
    if (c_.is_zero()) return zero();
    merge_spilled(spilled);
    const Expr result = node();
    if (guards_.empty()) return result;
    std::vector<Term> guarded{{result, Number::integer(1)}};
    for (Expr g : guards_) guarded.push_back({g, Number()});
    return pool_.sum(Number(), guarded);
  }

 private:
  static bool positive_integer(const Number& e) { return e.is_integer() && e.numerator() > 0; }

  // c times base^exponent. A power or product that overflows 64 bits is a real rounded once
  // (within one ulp, see number.hpp); it is folded no further but becomes a base (see sum()),
  // and c starts again from 1.
  void fold(const Number& base, std::int64_t exponent) {
    const Number power = base.pow(exponent);
    const Number folded = power.is_rational() ? c_ * power : power;
    if (folded.is_rational()) {
      c_ = folded;
    } else {
      overflowed_.push_back(folded);
      if (power.is_rational()) c_ = Number::integer(1);
    }
  }

  // One factor b^e into the coefficient, the entries or the guards.
  [[gnu::always_inline]] void collect(const Term& factor) {
    if (factor.expr.pool_ != &pool_) throw SymbolicError("expressions from different pools mixed");
    const Number& e = factor.factor;
    const std::uint32_t id = factor.expr.id_;
    const Node& node = impl_.nodes[id];
    if (e.is_zero()) {  // b^0 = 1 where b is defined
      if (node.partial) guards_.push_back(factor.expr);
      return;
    }
    const bool rational_constant = node.op == Op::kConstant && impl_.number_of(node).is_rational();
    if (rational_constant && e.is_integer()) {
      fold(impl_.number_of(node), e.numerator());
    } else if (rational_constant && impl_.number_of(node).is_one()) {
      return;
    } else if (positive_integer(e) && impl_.is_guard(id)) {
      // A guard sum 0·t1 + ... is zero wherever it is defined. To a positive integer power it
      // makes the product zero: the t_i join its factors as the domain guard, as the parser
      // reads "(0*t)*c" (0*t*c). (To a negative power it makes the product undefined everywhere:
      // undefined_product.)
      c_ = Number();
      for (std::uint32_t i = node.begin; i < node.begin + node.count; ++i) {
        entries_.emplace_back(impl_.operand_ids[i], Number::integer(1));
        required_.emplace_back(impl_.operand_ids[i], 0);
      }
    } else if (node.op == Op::kMul && e.is_integer() && node.count <= kFlattenLimit) {
      fold(impl_.number_of(node), e.numerator());
      may_hold_guard_ = may_hold_guard_ || node.partial;  // a guard is partial, so its products
      for (std::uint32_t i = node.begin; i < node.begin + node.count; ++i) {
        const Number inner = impl_.factor(i);
        // A guard under a negative power stays undefined whatever power the product is raised to.
        if (node.partial && inner.is_negative() && impl_.is_guard(impl_.operand_ids[i])) {
          undefined_ = true;
        }
        entries_.emplace_back(impl_.operand_ids[i], e * inner);
        required_.emplace_back(impl_.operand_ids[i],
                               domain_of_exponent(inner) | domain_of_exponent(e * inner));
      }
    } else {
      may_hold_guard_ = may_hold_guard_ || (node.op == Op::kAdd && node.partial);
      if (e.is_negative() && impl_.is_guard(id)) undefined_ = true;
      entries_.emplace_back(id, e);
      required_.emplace_back(id, domain_of_exponent(e));
    }
  }

  // Undefined everywhere: one form, (0·s1 + ...)^-1 over the terms s_j of every guard met,
  // whatever else the product held, so that a printed denominator "c/(a*(0*t))", which the
  // parser reads as c/(0*a*t), gives back the same node.
  Expr undefined_product() {
    std::vector<Term> guard_terms;
    for (const Entry& entry : entries_) {
      if (!impl_.is_guard(entry.first)) continue;
      const Node& guard = impl_.nodes[entry.first];
      for (std::uint32_t i = guard.begin; i < guard.begin + guard.count; ++i)
        guard_terms.push_back({Expr(&pool_, impl_.operand_ids[i]), Number()});
    }
    const Expr guard = pool_.sum(Number(), guard_terms);
    const auto begin = static_cast<std::uint32_t>(impl_.operand_ids.size());
    impl_.push_operand(guard.id(), impl_.number_index(Number::integer(-1)));
    return Expr(&pool_, impl_.intern(Op::kMul, impl_.one_index(), begin, 0));
  }

  // c = 0: the product is 0 wherever it is defined.
  Expr zero() {
    std::vector<Term> guard_terms;
    if (!entries_.empty()) {
      guard_terms.push_back(
          {pool_.product(Number::integer(1), pool_.terms_of(entries_)), Number()});
    }
    for (Expr g : guards_) guard_terms.push_back({g, Number()});
    return pool_.sum(Number(), guard_terms);  // drops what is defined everywhere
  }

  // A merged exponent may need less than its parts did (x·x^-1 = x^0, sqrt(x)^2 = x): guard the
  // base with the condition it lost, as b^-1 (b != 0), b^(1/2) (b >= 0) or b^(-1/2) (b > 0).
  void guard_lost_domains() {
    std::sort(required_.begin(), required_.end());
    for (std::size_t k = 0; k < required_.size();) {
      const std::uint32_t id = required_[k].first;
      int needed = 0;
      for (; k < required_.size() && required_[k].first == id; ++k) needed |= required_[k].second;
      const auto merged =
          std::lower_bound(entries_.begin(), entries_.end(), id,
                           [](const Entry& e, std::uint32_t v) { return e.first < v; });
      const bool present = merged != entries_.end() && merged->first == id;
      const int kept = present && merged->second.is_rational() ? domain_of_exponent(merged->second)
                                                               : (present ? needed : 0);
      const Node& base = impl_.nodes[id];
      if (base.op == Op::kConstant) needed &= impl_.number_of(base).sign() <= 0 ? kNonNegative : 0;
      const int lost = needed & ~kept;
      if (lost != 0) {
        const Number exponent = lost == (kNonZero | kNonNegative) ? Number::rational(-1, 2)
                                : lost == kNonZero                ? Number::integer(-1)
                                                                  : Number::rational(1, 2);
        guards_.push_back(pool_.power(Expr(&pool_, id), exponent));
      } else if (!present && base.partial) {
        guards_.push_back(Expr(&pool_, id));
      }
    }
  }

  // Merging may give a constant base an integer exponent (2^(1/2)·2^(1/2) = 2): fold it.
  void fold_constant_bases() {
    std::erase_if(entries_, [&](const Entry& entry) {
      const Node& node = impl_.nodes[entry.first];
      if (node.op != Op::kConstant || !impl_.number_of(node).is_rational() ||
          !entry.second.is_integer()) {
        return false;
      }
      fold(impl_.number_of(node), entry.second.numerator());
      return true;
    });
  }

  // The overflowed reals become bases (|real|, its sign into c); a spilled exponent that is real
  // (a sum that overflowed 64 bits) makes its factor the real power Pow(base, exponent) with
  // exponent 1; merge again until nothing spills.
  void merge_spilled(std::vector<Entry>& spilled) {
    for (const Number& real : overflowed_) {
      const bool negative = std::signbit(real.value());
      if (negative) c_ = -c_;
      spilled.emplace_back(pool_.constant(negative ? -real : real).id(), Number::integer(1));
    }
    while (!spilled.empty()) {
      for (const Entry& entry : std::exchange(spilled, {})) {
        if (entry.second.is_rational()) {
          entries_.push_back(entry);
        } else {
          entries_.emplace_back(pool_.power(Expr(&pool_, entry.first), entry.second).id(),
                                Number::integer(1));
        }
      }
      sort_and_merge(entries_, spilled);
    }
  }

  // c · Π b^e as its node: a constant, a lone base, a scaled sum distributed, or a Mul.
  Expr node() {
    if (entries_.empty()) return pool_.constant(c_);
    if (entries_.size() == 1 && entries_[0].second.is_one()) {
      const Expr only(&pool_, entries_[0].first);
      if (c_.is_one()) return only;
      // Distribute the coefficient: 2·(x + y) -> 2x + 2y. Not into a sum past the flattening
      // limit: sum() would keep it whole and hand the lone scaled term back here.
      if (only.op() == Op::kAdd && impl_.nodes[only.id()].count <= kFlattenLimit) {
        const Term scaled[] = {{only, c_}};
        return pool_.sum(Number(), scaled);
      }
    }
    return entries_node(Op::kMul, c_);
  }

  Number c_;
  // What the exponents of each base required (kNonZero / kNonNegative).
  LentVector<std::pair<std::uint32_t, int>> lent_required_;
  std::vector<std::pair<std::uint32_t, int>>& required_{*lent_required_};
  // Partial factors that folding removes: they come back as 0·guard terms so the result stays
  // undefined where the input was (x/x is 1 + 0·x^-1, 0·log(x) is 0·log(x)).
  std::vector<Expr> guards_;
  bool undefined_{false};
  bool may_hold_guard_{false};  // some entry's base may be a guard sum
};

Expr ExprPool::product(const Number& coefficient, std::span<const Term> factors) {
  if (!coefficient.is_rational()) {
    // Never folded (see sum()): |c| becomes a base and its sign the coefficient, the form the
    // parser gives "-c", so a real that overflowed survives print and parse.
    const bool negative = std::signbit(coefficient.value());
    std::vector<Term> all(factors.begin(), factors.end());
    all.push_back({constant(negative ? -coefficient : coefficient), Number::integer(1)});
    return product(Number::integer(negative ? -1 : 1), all);
  }
  return ProductForm(*this, coefficient).build(factors);
}

Expr ExprPool::sum(std::span<const Expr> terms) {
  std::vector<Term> t;
  t.reserve(terms.size());
  for (Expr e : terms) t.push_back({e, Number::integer(1)});
  return sum(Number(), t);
}

Expr ExprPool::product(std::span<const Expr> factors) {
  std::vector<Term> t;
  t.reserve(factors.size());
  for (Expr e : factors) t.push_back({e, Number::integer(1)});
  return product(Number::integer(1), t);
}

Expr ExprPool::power(Expr base, const Number& exponent) {
  if (!exponent.is_rational()) return power(base, constant(exponent));  // a real power: Pow
  const Term factor[] = {{base, exponent}};
  return product(Number::integer(1), factor);
}

Expr ExprPool::power(Expr base, Expr exponent) {
  if (base.pool_ != this || exponent.pool_ != this) {
    throw SymbolicError("expressions from different pools mixed");
  }
  if (exponent.is_constant() && exponent.constant().is_rational()) {
    return power(base, exponent.constant());
  }
  // A negative real exponent is -|r| (the product -1·|r|), the form the parser gives "-r", so
  // that printing and parsing give back the same node (fuzz finding: merged exponents that
  // overflow 64 bits become such a real).
  if (exponent.is_constant() && std::signbit(exponent.constant().value())) {
    return power(base, -constant(-exponent.constant()));
  }
  if (base.is_constant() && base.constant().is_one()) {  // 1^b = 1 where b is defined
    const Term guard[] = {{exponent, Number()}};
    return sum(Number::integer(1), guard);
  }
  const auto begin = static_cast<std::uint32_t>(impl_->operand_ids.size());
  impl_->push_operand(base.id_, impl_->one_index());
  impl_->push_operand(exponent.id_, impl_->one_index());
  return Expr(this, impl_->intern(Op::kPow, impl_->number_index_of_small(0), begin, 0));
}

Expr ExprPool::function(Op op, Expr argument) {
  if (!is_unary_function(op)) throw std::logic_error("ExprPool::function: not a unary function");
  if (argument.pool_ != this) throw SymbolicError("expressions from different pools mixed");
  if (argument.is_constant()) {
    const Number& v = argument.constant();
    const bool zero = v.is_zero(), one = v.is_one();
    switch (op) {
      case Op::kSin:
      case Op::kTan:
      case Op::kAtan:
      case Op::kAsin:
        if (zero) return argument;
        break;
      case Op::kCos:
      case Op::kExp:
        if (zero) return integer(1);
        break;
      case Op::kLog:
      case Op::kAcos:
        if (one) return integer(0);
        break;
      case Op::kAbs:
        if (v.sign() != 0 || zero) return constant(v.sign() < 0 ? -v : v);
        break;
      case Op::kSqrt:
        if (v.is_rational()) {
          const auto n = exact_isqrt(v.numerator()), d = exact_isqrt(v.denominator());
          if (n && d) return constant(Number::rational(*n, *d));
        }
        break;
      default:
        break;
    }
  }
  const auto begin = static_cast<std::uint32_t>(impl_->operand_ids.size());
  impl_->push_operand(argument.id_, impl_->one_index());
  return Expr(this, impl_->intern(op, impl_->number_index_of_small(0), begin, 0));
}

Expr ExprPool::function(Op op, Expr first, Expr second) {
  if (!is_binary_function(op)) throw std::logic_error("ExprPool::function: not a binary function");
  if (first.pool_ != this || second.pool_ != this) {
    throw SymbolicError("expressions from different pools mixed");
  }
  if (op == Op::kMin || op == Op::kMax) {
    if (first == second) return first;
    if (first.is_constant() && second.is_constant()) {
      const Number &a = first.constant(), &b = second.constant();
      // Fold only when the enclosures are ordered, so the choice is certain.
      if (a.upper() <= b.lower()) return op == Op::kMin ? first : second;
      if (b.upper() <= a.lower()) return op == Op::kMin ? second : first;
    }
    if (second.id_ < first.id_) std::swap(first, second);  // commutative: canonical order
  }
  const auto begin = static_cast<std::uint32_t>(impl_->operand_ids.size());
  for (Expr e : {first, second}) {
    impl_->push_operand(e.id_, impl_->one_index());
  }
  return Expr(this, impl_->intern(op, impl_->number_index_of_small(0), begin, 0));
}

void ExprPool::check_invariants() const {
  const Impl& m = *impl_;
  auto fail = [](std::uint32_t id, const std::string& what) {
    throw std::logic_error("expression node " + std::to_string(id) + ": " + what);
  };
  std::vector<bool> has_parent(m.nodes.size(), false);
  for (std::uint32_t id = 0; id < m.nodes.size(); ++id) {
    const Node& n = m.nodes[id];
    for (std::uint32_t i = n.begin; n.op != Op::kVariable && i < n.begin + n.count; ++i) {
      if (m.operand_ids[i] < has_parent.size()) has_parent[m.operand_ids[i]] = true;
    }
  }
  for (std::uint32_t id = 0; id < m.nodes.size(); ++id) {
    const Node& n = m.nodes[id];
    if (n.has_parent != has_parent[id]) fail(id, "wrong has_parent flag");
    if (n.number >= m.numbers.size()) fail(id, "number index out of range");
    for (std::uint32_t i = n.begin; n.op != Op::kVariable && i < n.begin + n.count; ++i) {
      if (m.factor_ids[i] >= m.numbers.size()) fail(id, "factor index out of range");
    }
    if (n.op == Op::kVariable || n.op == Op::kConstant) {
      if (n.count != 0) fail(id, "leaf with operands");
    } else {
      for (std::uint32_t i = n.begin; i < n.begin + n.count; ++i) {
        if (m.operand_ids[i] >= id) fail(id, "operand built after its parent");
        if (i > n.begin && (n.op == Op::kAdd || n.op == Op::kMul) &&
            m.operand_ids[i] <= m.operand_ids[i - 1]) {
          fail(id, "operands not strictly sorted by id");
        }
        if (m.factor(i).is_zero() && !(n.op == Op::kAdd && m.nodes[m.operand_ids[i]].partial)) {
          fail(id, "zero coefficient (on a term defined everywhere) or exponent");
        }
        const Node& child = m.nodes[m.operand_ids[i]];
        if (n.op == Op::kAdd) {
          if (child.op == Op::kConstant && m.number_of(child).is_rational())
            fail(id, "constant sum term");
          if (child.op == Op::kAdd && child.count <= kFlattenLimit)
            fail(id, "unflattened sum term");
          if (child.op == Op::kMul && !m.number_of(child).is_one())
            fail(id, "sum term with coefficient");
        }
        if (n.op == Op::kMul) {
          if (child.op == Op::kConstant && m.number_of(child).is_rational() &&
              m.factor(i).is_integer()) {
            fail(id, "unfolded constant");
          }
          if (child.op == Op::kMul && m.factor(i).is_integer() && child.count <= kFlattenLimit) {
            fail(id, "unflattened product");
          }
        }
      }
    }
    if ((n.op == Op::kAdd || n.op == Op::kMul) && !m.number_of(n).is_rational()) {
      fail(id, "real constant folded into a sum or product");
    }
    if (n.op == Op::kAdd && (n.count == 0 || (n.count == 1 && m.number_of(n).is_zero() &&
                                              !m.factor(n.begin).is_zero()))) {
      fail(id, "degenerate sum");
    }
    if (n.op == Op::kMul) {
      if (n.count == 0 || m.number_of(n).is_zero()) fail(id, "degenerate product");
      if (n.count == 1 && m.number_of(n).is_one() && m.factor(n.begin).is_one())
        fail(id, "trivial product");
    }
    if (n.op == Op::kPow) {
      const Node& exponent = m.nodes[m.operand_ids[n.begin + 1]];
      if (exponent.op == Op::kConstant &&
          (m.number_of(exponent).is_rational() || std::signbit(m.number_of(exponent).value())))
        fail(id, "Pow with a rational or negative real constant exponent");
    }
    if (n.partial != m.partial_node(n.op, n.begin, n.count)) fail(id, "wrong partial flag");
    const std::uint32_t key = key_of(m.node_hash(id));
    std::size_t s = m.table.home(key);
    for (; m.table.slot(s).id != id; s = m.table.next(s)) {
      const std::uint32_t other = m.table.slot(s).id;
      if (other == kEmptySlot) fail(id, "missing from the hash-consing table");
      if (m.same_node(other, id)) fail(id, "duplicate of node " + std::to_string(other));
    }
    if (m.table.slot(s).key != key) fail(id, "wrong key in the table");
    if (n.op == Op::kVariable &&
        m.find_variable(m.names[n.begin], ExprPool::Impl::name_key(m.names[n.begin])) != id) {
      fail(id, "variable missing from the table of names");
    }
  }
  // numbers: each distinct value once, found by its index.
  for (std::uint32_t i = 0; i < m.numbers.size(); ++i) {
    const Number& value = m.numbers[i];
    const std::uint32_t found = ExprPool::Impl::is_small_integer(value)
                                    ? m.small_integers[value.numerator() + kSmallInteger] - 1
                                    : m.find_number(value, ExprPool::Impl::number_key(value));
    if (found != i) {
      throw std::logic_error("pool number " + std::to_string(i) + " (" + value.to_string() +
                             ") stored twice or missing from its table");
    }
  }
}

std::vector<Expr> topological_order(std::span<const Expr> roots) {
  std::vector<Expr> order;
  if (roots.empty()) return order;
  ExprPool* pool = &roots[0].pool();
  ExprPool::Impl& m = *pool->impl_;
  m.marks.resize(m.nodes.size(), 0);
  if (++m.epoch == 0) {  // wrapped: reset all marks
    std::fill(m.marks.begin(), m.marks.end(), 0);
    m.epoch = 1;
  }
  // Explicit stack (empty between calls): no recursion, any depth.
  std::vector<std::pair<std::uint32_t, std::uint32_t>>& stack = m.traversal;
  order.reserve(128);
  for (Expr root : roots) {
    if (&root.pool() != pool) throw SymbolicError("expressions from different pools mixed");
    if (m.marks[root.id()] == m.epoch) continue;
    m.marks[root.id()] = m.epoch;
    stack.emplace_back(root.id(), 0);
    while (!stack.empty()) {
      auto& [id, next] = stack.back();
      const Node& node = m.nodes[id];
      if (next < node.count) {
        const std::uint32_t child = m.operand_ids[node.begin + next++];
        if (m.marks[child] != m.epoch) {
          m.marks[child] = m.epoch;
          stack.emplace_back(child, 0);
        }
      } else {
        order.push_back(Expr(pool, id));
        stack.pop_back();
      }
    }
  }
  return order;
}

// ---------------------------------------------------------------------------------------------
// Operators and functions

namespace {
const Number kMinusOne = Number::integer(-1);
}  // namespace

// Shortcuts that give what sum() and product() would, without building anything: a + 0 = a,
// a·1 = a, and a·0 = 0 when a is defined everywhere (else 0·a keeps a as a guard). Mixed pools
// go on to sum() and product(), which report them.
Expr operator+(Expr a, Expr b) {
  if (&a.pool() == &b.pool()) {
    const ExprPool::Impl& m = *a.pool().impl_;
    if (m.is_integer_constant(b.id(), 0)) return a;
    if (m.is_integer_constant(a.id(), 0)) return b;
  }
  const Term terms[] = {{a, Number::one()}, {b, Number::one()}};
  return a.pool().sum(Number(), terms);
}
Expr operator-(Expr a, Expr b) {
  const Term terms[] = {{a, Number::one()}, {b, kMinusOne}};
  return a.pool().sum(Number(), terms);
}
Expr operator*(Expr a, Expr b) {
  if (&a.pool() == &b.pool()) {
    const ExprPool::Impl& m = *a.pool().impl_;
    if (m.is_integer_constant(b.id(), 1)) return a;
    if (m.is_integer_constant(a.id(), 1)) return b;
    if (m.is_integer_constant(b.id(), 0) && !m.nodes[a.id()].partial) return b;
    if (m.is_integer_constant(a.id(), 0) && !m.nodes[b.id()].partial) return a;
  }
  const Term factors[] = {{a, Number::one()}, {b, Number::one()}};
  return a.pool().product(Number::one(), factors);
}
Expr operator/(Expr a, Expr b) {
  const Term factors[] = {{a, Number::one()}, {b, kMinusOne}};
  return a.pool().product(Number::one(), factors);
}
Expr operator-(Expr a) {
  const Term factors[] = {{a, Number::one()}};
  return a.pool().product(kMinusOne, factors);
}
Expr operator+(Expr a, double b) { return a + a.pool().constant(b); }
Expr operator+(double a, Expr b) { return b.pool().constant(a) + b; }
Expr operator-(Expr a, double b) { return a - a.pool().constant(b); }
Expr operator-(double a, Expr b) { return b.pool().constant(a) - b; }
Expr operator*(Expr a, double b) { return a * a.pool().constant(b); }
Expr operator*(double a, Expr b) { return b.pool().constant(a) * b; }
Expr operator/(Expr a, double b) { return a / a.pool().constant(b); }
Expr operator/(double a, Expr b) { return b.pool().constant(a) / b; }
Expr& operator+=(Expr& a, Expr b) { return a = a + b; }
Expr& operator-=(Expr& a, Expr b) { return a = a - b; }
Expr& operator*=(Expr& a, Expr b) { return a = a * b; }

Expr pow(Expr base, Expr exponent) { return base.pool().power(base, exponent); }
Expr pow(Expr base, const Number& exponent) { return base.pool().power(base, exponent); }
Expr pow(Expr base, std::int64_t exponent) {
  return base.pool().power(base, Number::integer(exponent));
}
#define SPAR_DEFINE_UNARY(Name, name, ...) \
  Expr name(Expr a) { return a.pool().function(Op::k##Name, a); }
#define SPAR_DEFINE_BINARY(Name, name, ...) \
  Expr name(Expr a, Expr b) { return a.pool().function(Op::k##Name, a, b); }
SPAR_UNARY_FUNCTIONS(SPAR_DEFINE_UNARY)
SPAR_BINARY_FUNCTIONS(SPAR_DEFINE_BINARY)
#undef SPAR_DEFINE_UNARY
#undef SPAR_DEFINE_BINARY

}  // namespace spar::symbolic
