// Dempster-Shafer evidence over a finite frame of discernment (Shafer 1976): the uncertainty
// calculus of the survey's sensor planner (seed 003, section 3) and of PSEIKI (section 4).
//
// Frame: n named hypotheses, mutually exclusive and together exhaustive (1 <= n <= kMaxFrameSize).
// FocalSet: a subset of a frame as a bitset (bit i = hypothesis i), so intersection, subset and
//   cardinality are word operations; sets of frames up to 128 hypotheses live inline (no
//   allocation).
// MassFunction: a basic probability assignment m: 2^frame -> [0, 1], stored sparsely as its focal
//   elements (the sets with m > 0). Invariants (checked on construction, SensingError otherwise):
//   every focal set belongs to the frame and is not empty; every mass is finite and > 0; the
//   masses sum to 1 (inputs within 1e-9 are rescaled to 1); the elements are sorted by FocalSet's
//   order without repeats. debug_check() re-checks them.
//
// Dempster's rule:  (m1 (+) m2)(A) = sum_{B ∩ C = A} m1(B) m2(C) / (1 - K),  A != {},
//   K = sum_{B ∩ C = {}} m1(B) m2(C), the conflict, reported with the result. 1 - K is summed
//   from the non-empty products (not computed as 1 - K), so a conflict near 1 keeps its digits;
//   total conflict (no two focal sets meet) throws SensingError: the sources contradict each
//   other outright and there is nothing to normalise. Combining many sources folds the rule
//   (it is commutative and associative) and reports the overall conflict 1 - prod_i (1 - K_i),
//   the mass the unnormalised conjunctive combination of all of them puts on the empty set.
// Belief Bel(A) = sum_{B ⊆ A} m(B); plausibility Pl(A) = sum_{B ∩ A != {}} m(B) = 1 - Bel(not A);
// pignistic probability BetP(x) = sum_{B ∋ x} m(B) / |B| (Smets' transferable belief model).
//
// Ambiguity (the measure the survey calls "based on the entropy measure"): the entropy of the
//   pignistic probability, AM(m) = -sum_x BetP(x) log2 BetP(x) bits (Jousselme, Liu, Grenier and
//   Bossé, "Measuring ambiguity in the evidence theory", IEEE SMC-A 36(5), 2006). It is 0 exactly
//   when one hypothesis has all of BetP, and log2 n for the vacuous mass or a uniform Bayesian one.
//   The selection of sensing operations (selection.hpp) minimises the maximum of this measure.
//   Nonspecificity N(m) = sum_A m(A) log2 |A| (Dubois and Prade's generalised Hartley measure) is
//   reported beside it; it is 0 for every Bayesian m however spread, so it is not used alone.
//
// Refinement (the survey's "expand the frame of discernment as new features are found"): a
//   refining maps each coarse hypothesis i to a non-empty set w(i) of a finer frame, the sets
//   disjoint and covering it (block -> {block in P1, block in P3, ...}). refine() is the vacuous
//   extension m'(w(A)) = m(A); coarsen() its outer reduction back, m(B) = sum of m'(A) over the A
//   whose coarse image {i : w(i) ∩ A != {}} is B; coarsen(refine(m)) == m.
//
// Cost: combine(a, b) visits |a|·|b| pairs of focal elements, O(w) each for w = ceil(n / 64)
// words, and hashes the intersections; the result has at most min(|a|·|b|, 2^n - 1) elements.
// Bel, Pl and BetP cost O(|m| w). No dense 2^n table is ever built.
//
// Example:
//   const Frame frame({"block", "cube", "peg"});
//   const MassFunction a = MassFunction::simple_support(frame.set({"block", "cube"}), 0.8);
//   const MassFunction b = MassFunction::simple_support(frame.set({"cube", "peg"}), 0.6);
//   const Combination both = combine(a, b);        // m({cube}) = 0.48, conflict 0
//   const double bel = both.mass.belief(frame.set({"cube"}));   // 0.48
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace spar::sensing {

// The largest frame: far above what hypothesis sets need (tens of poses, a few hundred labels).
inline constexpr int kMaxFrameSize = 1 << 16;

// A subset of a frame of `frame_size()` hypotheses. Invariant: the words (inline_ for frames of up
// to 128 hypotheses, heap_ beyond, the other one empty or zero) are ceil(size / 64) and every bit
// at or above `size` is 0, so equal sets have equal words.
class FocalSet {
 public:
  FocalSet() = default;  // the empty set of an empty frame; only a placeholder
  // The empty subset of a frame of `frame_size` hypotheses (1..kMaxFrameSize, else SensingError).
  explicit FocalSet(int frame_size);
  [[nodiscard]] static FocalSet whole(int frame_size);
  [[nodiscard]] static FocalSet of(int frame_size, std::initializer_list<int> members);

  [[nodiscard]] int frame_size() const { return size_; }
  [[nodiscard]] bool contains(int hypothesis) const;
  void insert(int hypothesis);  // SensingError when outside the frame
  [[nodiscard]] int count() const;
  [[nodiscard]] bool empty() const;
  [[nodiscard]] std::vector<int> members() const;  // ascending
  [[nodiscard]] bool is_subset_of(const FocalSet& other) const;
  [[nodiscard]] bool intersects(const FocalSet& other) const;
  [[nodiscard]] FocalSet complement() const;
  // Set operations need sets of one frame size (SensingError otherwise).
  [[nodiscard]] FocalSet operator&(const FocalSet& other) const;
  [[nodiscard]] FocalSet operator|(const FocalSet& other) const;
  [[nodiscard]] bool operator==(const FocalSet& other) const;
  // Canonical order: fewer members first, then by the ascending list of members.
  [[nodiscard]] bool operator<(const FocalSet& other) const;
  [[nodiscard]] std::size_t hash() const;

 private:
  void require_same_frame(const FocalSet& other) const;
  [[nodiscard]] std::span<std::uint64_t> words();
  [[nodiscard]] std::span<const std::uint64_t> words() const;
  static constexpr int kInlineWords = 2;
  int size_{0};
  std::array<std::uint64_t, kInlineWords> inline_{};
  std::vector<std::uint64_t> heap_;
};

struct FocalSetHash {
  std::size_t operator()(const FocalSet& set) const { return set.hash(); }
};

// n named hypotheses. Names are non-empty and distinct (SensingError otherwise).
class Frame {
 public:
  explicit Frame(std::vector<std::string> names);
  [[nodiscard]] int size() const { return static_cast<int>(names_.size()); }
  [[nodiscard]] const std::string& name(int hypothesis) const { return names_.at(hypothesis); }
  [[nodiscard]] const std::vector<std::string>& names() const { return names_; }
  // The index of `name`, or SensingError listing the frame.
  [[nodiscard]] int index(std::string_view name) const;
  [[nodiscard]] FocalSet set(std::initializer_list<std::string_view> names) const;
  [[nodiscard]] FocalSet set(std::span<const std::string> names) const;
  [[nodiscard]] FocalSet whole() const { return FocalSet::whole(size()); }
  [[nodiscard]] std::vector<std::string> names_of(const FocalSet& set) const;

 private:
  std::vector<std::string> names_;
};

struct Combination;

struct FocalElement {
  FocalSet set;
  double mass{0};
};

class MassFunction {
 public:
  // The vacuous mass function of a frame of one hypothesis (a placeholder value).
  MassFunction();
  // The vacuous mass function m(frame) = 1: total ignorance, the identity of Dempster's rule.
  [[nodiscard]] static MassFunction vacuous(int frame_size);
  // m(set) = support, m(frame) = 1 - support (support in [0, 1], set not empty).
  [[nodiscard]] static MassFunction simple_support(const FocalSet& set, double support);
  // m({x}) = probabilities[x]: a Bayesian mass function (non-negative, summing to 1).
  [[nodiscard]] static MassFunction bayesian(std::span<const double> probabilities);
  // Any assignment: repeated sets are merged, zero masses dropped; SensingError for a set of
  // another frame, an empty set with mass, a mass outside [0, 1] or a sum other than 1.
  [[nodiscard]] static MassFunction from_elements(int frame_size,
                                                  std::vector<FocalElement> elements);

  [[nodiscard]] int frame_size() const { return frame_size_; }
  [[nodiscard]] const std::vector<FocalElement>& elements() const { return elements_; }
  [[nodiscard]] double mass(const FocalSet& set) const;  // 0 when not focal
  [[nodiscard]] double belief(const FocalSet& set) const;
  [[nodiscard]] double plausibility(const FocalSet& set) const;
  [[nodiscard]] std::vector<double> pignistic() const;  // BetP(x) for each hypothesis x
  [[nodiscard]] double ambiguity() const;               // entropy of BetP, bits
  [[nodiscard]] double nonspecificity() const;          // sum m(A) log2 |A|, bits
  // Throws std::logic_error naming the broken invariant (tests and debug builds call it).
  void debug_check() const;

 private:
  friend Combination combine(const MassFunction& a, const MassFunction& b);
  int frame_size_{0};
  std::vector<FocalElement> elements_;  // sorted by set, distinct, masses > 0 summing to 1
};

struct Combination {
  MassFunction mass;
  double conflict{0};  // K in [0, 1)
};

// Dempster's rule; SensingError for total conflict or for frames of different sizes.
[[nodiscard]] Combination combine(const MassFunction& a, const MassFunction& b);
// All `sources` in order (none: the vacuous mass of `frame_size`); overall conflict as above.
[[nodiscard]] Combination combine(std::span<const MassFunction> sources, int frame_size);

// A refining of a frame of refining.size() hypotheses into one of `fine_size`: SensingError
// unless every set is a non-empty subset of the fine frame, they are disjoint and they cover it.
void check_refining(std::span<const FocalSet> refining, int fine_size);
[[nodiscard]] MassFunction refine(const MassFunction& coarse, std::span<const FocalSet> refining);
[[nodiscard]] MassFunction coarsen(const MassFunction& fine, std::span<const FocalSet> refining);

}  // namespace spar::sensing
