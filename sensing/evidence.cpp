#include "spar/sensing/evidence.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "spar/common/number.hpp"
#include "spar/sensing/error.hpp"

namespace spar::sensing {
namespace {

constexpr int kWordBits = 64;
// How far the masses of an assignment may sum from 1 before it is refused (then it is rescaled).
constexpr double kSumTolerance = 1e-9;

int word_count(int frame_size) { return (frame_size + kWordBits - 1) / kWordBits; }

void check_frame_size(int frame_size) {
  if (frame_size < 1 || frame_size > kMaxFrameSize)
    throw SensingError("a frame needs 1 to " + std::to_string(kMaxFrameSize) + " hypotheses, got " +
                       std::to_string(frame_size));
}

bool by_set(const FocalElement& a, const FocalElement& b) { return a.set < b.set; }

}  // namespace

// ---- FocalSet ----

FocalSet::FocalSet(int frame_size) : size_(frame_size) {
  check_frame_size(frame_size);
  if (const int count = word_count(frame_size); count > kInlineWords)
    heap_.assign(static_cast<std::size_t>(count), 0);
}

std::span<std::uint64_t> FocalSet::words() {
  const auto count = static_cast<std::size_t>(word_count(size_));
  return heap_.empty() ? std::span<std::uint64_t>(inline_.data(), count)
                       : std::span<std::uint64_t>(heap_);
}

std::span<const std::uint64_t> FocalSet::words() const {
  const auto count = static_cast<std::size_t>(word_count(size_));
  return heap_.empty() ? std::span<const std::uint64_t>(inline_.data(), count)
                       : std::span<const std::uint64_t>(heap_);
}

FocalSet FocalSet::whole(int frame_size) {
  FocalSet set(frame_size);
  const std::span<std::uint64_t> words = set.words();
  for (std::uint64_t& word : words) word = ~std::uint64_t{0};
  if (const int spare = frame_size % kWordBits; spare != 0)
    words.back() = (std::uint64_t{1} << spare) - 1;
  return set;
}

FocalSet FocalSet::of(int frame_size, std::initializer_list<int> members) {
  FocalSet set(frame_size);
  for (const int member : members) set.insert(member);
  return set;
}

bool FocalSet::contains(int hypothesis) const {
  if (hypothesis < 0 || hypothesis >= size_) return false;
  return (words()[static_cast<std::size_t>(hypothesis / kWordBits)] >> (hypothesis % kWordBits)) &
         1U;
}

void FocalSet::insert(int hypothesis) {
  if (hypothesis < 0 || hypothesis >= size_)
    throw SensingError("hypothesis " + std::to_string(hypothesis) + " is outside a frame of " +
                       std::to_string(size_));
  words()[static_cast<std::size_t>(hypothesis / kWordBits)] |= std::uint64_t{1}
                                                               << (hypothesis % kWordBits);
}

int FocalSet::count() const {
  int total = 0;
  for (const std::uint64_t word : words()) total += std::popcount(word);
  return total;
}

bool FocalSet::empty() const {
  const std::span<const std::uint64_t> all = words();
  return std::all_of(all.begin(), all.end(), [](std::uint64_t word) { return word == 0; });
}

std::vector<int> FocalSet::members() const {
  std::vector<int> out;
  const std::span<const std::uint64_t> all = words();
  for (std::size_t w = 0; w < all.size(); ++w)
    for (std::uint64_t word = all[w]; word != 0; word &= word - 1)
      out.push_back(static_cast<int>(w) * kWordBits + std::countr_zero(word));
  return out;
}

void FocalSet::require_same_frame(const FocalSet& other) const {
  if (size_ != other.size_)
    throw SensingError("focal sets of frames of different sizes (" + std::to_string(size_) +
                       " and " + std::to_string(other.size_) + " hypotheses)");
}

bool FocalSet::is_subset_of(const FocalSet& other) const {
  require_same_frame(other);
  const std::span<const std::uint64_t> mine = words(), theirs = other.words();
  for (std::size_t w = 0; w < mine.size(); ++w)
    if (mine[w] & ~theirs[w]) return false;
  return true;
}

bool FocalSet::intersects(const FocalSet& other) const {
  require_same_frame(other);
  const std::span<const std::uint64_t> mine = words(), theirs = other.words();
  for (std::size_t w = 0; w < mine.size(); ++w)
    if (mine[w] & theirs[w]) return true;
  return false;
}

FocalSet FocalSet::complement() const {
  FocalSet out = whole(size_);
  const std::span<const std::uint64_t> mine = words();
  const std::span<std::uint64_t> result = out.words();
  for (std::size_t w = 0; w < mine.size(); ++w) result[w] &= ~mine[w];
  return out;
}

FocalSet FocalSet::operator&(const FocalSet& other) const {
  require_same_frame(other);
  FocalSet out = *this;
  const std::span<std::uint64_t> result = out.words();
  const std::span<const std::uint64_t> theirs = other.words();
  for (std::size_t w = 0; w < result.size(); ++w) result[w] &= theirs[w];
  return out;
}

FocalSet FocalSet::operator|(const FocalSet& other) const {
  require_same_frame(other);
  FocalSet out = *this;
  const std::span<std::uint64_t> result = out.words();
  const std::span<const std::uint64_t> theirs = other.words();
  for (std::size_t w = 0; w < result.size(); ++w) result[w] |= theirs[w];
  return out;
}

bool FocalSet::operator==(const FocalSet& other) const {
  if (size_ != other.size_) return false;
  const std::span<const std::uint64_t> mine = words(), theirs = other.words();
  return std::equal(mine.begin(), mine.end(), theirs.begin());
}

bool FocalSet::operator<(const FocalSet& other) const {
  if (size_ != other.size_) return size_ < other.size_;
  const int a = count(), b = other.count();
  if (a != b) return a < b;
  // Equal counts: the set holding the lowest member of the symmetric difference has the smaller
  // member at the first position where the ascending member lists differ.
  const std::span<const std::uint64_t> mine = words(), theirs = other.words();
  for (std::size_t w = 0; w < mine.size(); ++w)
    if (const std::uint64_t difference = mine[w] ^ theirs[w]; difference != 0)
      return (mine[w] & (difference & (~difference + 1))) != 0;
  return false;
}

std::size_t FocalSet::hash() const {
  std::uint64_t h = 0x9E3779B97F4A7C15ULL ^ static_cast<std::uint64_t>(size_);
  for (const std::uint64_t word : words()) {
    h ^= word + 0x9E3779B97F4A7C15ULL + (h << 6) + (h >> 2);
    h *= 0xBF58476D1CE4E5B9ULL;
  }
  return static_cast<std::size_t>(h ^ (h >> 31));
}

// ---- Frame ----

Frame::Frame(std::vector<std::string> names) : names_(std::move(names)) {
  if (names_.empty() || static_cast<int>(names_.size()) > kMaxFrameSize)
    throw SensingError("a frame needs 1 to " + std::to_string(kMaxFrameSize) + " hypotheses, got " +
                       std::to_string(names_.size()));
  std::unordered_map<std::string_view, int> seen;
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i].empty())
      throw SensingError("frame: hypothesis " + std::to_string(i) + " has an empty name");
    if (!seen.emplace(names_[i], static_cast<int>(i)).second)
      throw SensingError("frame: hypothesis '" + names_[i] + "' is listed twice");
  }
}

int Frame::index(std::string_view name) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == name) return static_cast<int>(i);
  std::string known;
  for (const std::string& each : names_) known += (known.empty() ? "" : ", ") + each;
  throw SensingError("'" + std::string(name) + "' is not a hypothesis of the frame (" + known +
                     ")");
}

FocalSet Frame::set(std::initializer_list<std::string_view> names) const {
  FocalSet out(size());
  for (const std::string_view name : names) out.insert(index(name));
  return out;
}

FocalSet Frame::set(std::span<const std::string> names) const {
  FocalSet out(size());
  for (const std::string& name : names) out.insert(index(name));
  return out;
}

std::vector<std::string> Frame::names_of(const FocalSet& set) const {
  if (set.frame_size() != size())
    throw SensingError("a set of a frame of " + std::to_string(set.frame_size()) +
                       " hypotheses named with a frame of " + std::to_string(size()));
  std::vector<std::string> out;
  for (const int member : set.members()) out.push_back(names_[static_cast<std::size_t>(member)]);
  return out;
}

// ---- MassFunction ----

MassFunction::MassFunction() : frame_size_(1), elements_{{FocalSet::whole(1), 1.0}} {}

MassFunction MassFunction::vacuous(int frame_size) {
  MassFunction m;
  m.frame_size_ = frame_size;
  m.elements_.assign(1, {FocalSet::whole(frame_size), 1.0});
  return m;
}

MassFunction MassFunction::simple_support(const FocalSet& set, double support) {
  if (!(support >= 0 && support <= 1))
    throw SensingError("a simple support function's support must be in [0, 1], got " +
                       format_number(support));
  return from_elements(set.frame_size(),
                       {{set, support}, {FocalSet::whole(set.frame_size()), 1 - support}});
}

MassFunction MassFunction::bayesian(std::span<const double> probabilities) {
  const int n = static_cast<int>(probabilities.size());
  std::vector<FocalElement> elements;
  for (int x = 0; x < n; ++x) elements.push_back({FocalSet::of(n, {x}), probabilities[x]});
  return from_elements(n, std::move(elements));
}

MassFunction MassFunction::from_elements(int frame_size, std::vector<FocalElement> elements) {
  check_frame_size(frame_size);
  std::unordered_map<FocalSet, double, FocalSetHash> merged;
  double sum = 0;
  for (const FocalElement& element : elements) {
    if (element.set.frame_size() != frame_size)
      throw SensingError("a focal set of a frame of " + std::to_string(element.set.frame_size()) +
                         " hypotheses in a mass function over " + std::to_string(frame_size));
    if (!(element.mass >= 0 && element.mass <= 1))
      throw SensingError("a mass must be in [0, 1], got " + format_number(element.mass));
    if (element.mass == 0) continue;
    if (element.set.empty())
      throw SensingError("the empty set cannot carry mass (got " + format_number(element.mass) +
                         "): a source's masses go to non-empty sets");
    merged[element.set] += element.mass;
    sum += element.mass;
  }
  if (!(std::abs(sum - 1) <= kSumTolerance))
    throw SensingError("the masses of a source must sum to 1, got " + format_number(sum));
  MassFunction m;
  m.frame_size_ = frame_size;
  m.elements_.clear();
  m.elements_.reserve(merged.size());
  for (const auto& [set, mass] : merged) m.elements_.push_back({set, mass / sum});
  std::sort(m.elements_.begin(), m.elements_.end(), by_set);
  return m;
}

double MassFunction::mass(const FocalSet& set) const {
  const auto found = std::lower_bound(
      elements_.begin(), elements_.end(), set,
      [](const FocalElement& element, const FocalSet& key) { return element.set < key; });
  return found != elements_.end() && found->set == set ? found->mass : 0.0;
}

double MassFunction::belief(const FocalSet& set) const {
  double total = 0;
  for (const FocalElement& element : elements_)
    if (element.set.is_subset_of(set)) total += element.mass;
  return total;
}

double MassFunction::plausibility(const FocalSet& set) const {
  double total = 0;
  for (const FocalElement& element : elements_)
    if (element.set.intersects(set)) total += element.mass;
  return total;
}

std::vector<double> MassFunction::pignistic() const {
  std::vector<double> probability(static_cast<std::size_t>(frame_size_), 0.0);
  for (const FocalElement& element : elements_) {
    const std::vector<int> members = element.set.members();
    const double share = element.mass / static_cast<double>(members.size());
    for (const int x : members) probability[static_cast<std::size_t>(x)] += share;
  }
  return probability;
}

double MassFunction::ambiguity() const {
  double entropy = 0;
  for (const double p : pignistic())
    if (p > 0) entropy -= p * std::log2(p);
  return std::max(entropy, 0.0);
}

double MassFunction::nonspecificity() const {
  double total = 0;
  for (const FocalElement& element : elements_)
    total += element.mass * std::log2(static_cast<double>(element.set.count()));
  return total;
}

void MassFunction::debug_check() const {
  double sum = 0;
  for (std::size_t i = 0; i < elements_.size(); ++i) {
    const FocalElement& element = elements_[i];
    if (element.set.frame_size() != frame_size_)
      throw std::logic_error("MassFunction: a focal set of another frame");
    if (element.set.empty()) throw std::logic_error("MassFunction: mass on the empty set");
    if (!(element.mass > 0 && std::isfinite(element.mass)))
      throw std::logic_error("MassFunction: a mass that is not finite and > 0");
    if (i > 0 && !(elements_[i - 1].set < element.set))
      throw std::logic_error("MassFunction: elements not sorted or repeated");
    sum += element.mass;
  }
  if (!(std::abs(sum - 1) <= 1e-9)) throw std::logic_error("MassFunction: masses do not sum to 1");
}

// ---- Dempster's rule ----

namespace {

// The unnormalised conjunctive combination: the non-empty intersections with their summed
// products, and the summed products on the empty set and off it.
struct Conjunction {
  std::unordered_map<FocalSet, double, FocalSetHash> masses;
  double agreeing{0};  // sum of the products on non-empty sets = 1 - K
  double conflict{0};  // sum of the products on the empty set = K
};

Conjunction conjunction(const MassFunction& a, const MassFunction& b) {
  if (a.frame_size() != b.frame_size())
    throw SensingError("Dempster's rule: mass functions over frames of different sizes (" +
                       std::to_string(a.frame_size()) + " and " + std::to_string(b.frame_size()) +
                       " hypotheses)");
  Conjunction out;
  out.masses.reserve(a.elements().size() * b.elements().size());
  for (const FocalElement& x : a.elements())
    for (const FocalElement& y : b.elements()) {
      const double product = x.mass * y.mass;
      if (product == 0) continue;  // underflow: no mass to carry
      FocalSet meet = x.set & y.set;
      if (meet.empty()) {
        out.conflict += product;
      } else {
        out.masses[std::move(meet)] += product;
        out.agreeing += product;
      }
    }
  return out;
}

}  // namespace

Combination combine(const MassFunction& a, const MassFunction& b) {
  Conjunction joint = conjunction(a, b);
  if (joint.agreeing <= 0 || joint.masses.empty())
    throw SensingError(
        "Dempster's rule: total conflict (K = 1): no focal set of one source meets one of the "
        "other, so the sources contradict each other and cannot be combined");
  Combination out{MassFunction(), joint.conflict / (joint.conflict + joint.agreeing)};
  out.mass.frame_size_ = a.frame_size();
  out.mass.elements_.clear();
  out.mass.elements_.reserve(joint.masses.size());
  for (auto& [set, mass] : joint.masses)
    if (const double normalised = mass / joint.agreeing; normalised > 0)
      out.mass.elements_.push_back({set, normalised});
  std::sort(out.mass.elements_.begin(), out.mass.elements_.end(), by_set);
  return out;
}

Combination combine(std::span<const MassFunction> sources, int frame_size) {
  Combination out{MassFunction::vacuous(frame_size), 0.0};
  double agreeing = 1;  // prod_i (1 - K_i)
  for (const MassFunction& source : sources) {
    Combination next = combine(out.mass, source);
    agreeing *= 1 - next.conflict;
    out.mass = std::move(next.mass);
  }
  out.conflict = 1 - agreeing;
  return out;
}

// ---- refinement ----

void check_refining(std::span<const FocalSet> refining, int fine_size) {
  if (refining.empty()) throw SensingError("a refining needs at least one coarse hypothesis");
  FocalSet covered(fine_size);
  for (std::size_t i = 0; i < refining.size(); ++i) {
    const FocalSet& image = refining[i];
    if (image.frame_size() != fine_size)
      throw SensingError("refining: coarse hypothesis " + std::to_string(i) +
                         " maps into a frame of " + std::to_string(image.frame_size()) +
                         " hypotheses, not " + std::to_string(fine_size));
    if (image.empty())
      throw SensingError("refining: coarse hypothesis " + std::to_string(i) +
                         " maps to no fine hypothesis");
    if (image.intersects(covered))
      throw SensingError("refining: coarse hypothesis " + std::to_string(i) +
                         " shares fine hypotheses with an earlier one");
    covered = covered | image;
  }
  if (covered.count() != fine_size)
    throw SensingError("refining: the fine hypotheses " +
                       std::to_string(fine_size - covered.count()) +
                       " are not the image of any coarse hypothesis");
}

MassFunction refine(const MassFunction& coarse, std::span<const FocalSet> refining) {
  if (static_cast<int>(refining.size()) != coarse.frame_size())
    throw SensingError("refine: a refining of " + std::to_string(refining.size()) +
                       " hypotheses for a mass function over " +
                       std::to_string(coarse.frame_size()));
  const int fine_size = refining.front().frame_size();
  check_refining(refining, fine_size);
  std::vector<FocalElement> elements;
  for (const FocalElement& element : coarse.elements()) {
    FocalSet image(fine_size);
    for (const int i : element.set.members()) image = image | refining[static_cast<std::size_t>(i)];
    elements.push_back({std::move(image), element.mass});
  }
  return MassFunction::from_elements(fine_size, std::move(elements));
}

MassFunction coarsen(const MassFunction& fine, std::span<const FocalSet> refining) {
  check_refining(refining, fine.frame_size());
  const int coarse_size = static_cast<int>(refining.size());
  std::vector<FocalElement> elements;
  for (const FocalElement& element : fine.elements()) {
    FocalSet image(coarse_size);
    for (int i = 0; i < coarse_size; ++i)
      if (refining[static_cast<std::size_t>(i)].intersects(element.set)) image.insert(i);
    elements.push_back({std::move(image), element.mass});
  }
  return MassFunction::from_elements(coarse_size, std::move(elements));
}

}  // namespace spar::sensing
