// The brute-force reference for Dempster-Shafer evidence (tests only): mass functions as dense
// tables over all 2^n subsets of a frame of n <= 6 hypotheses (subsets as bitmasks, 0 = the empty
// set), Dempster's rule as the double loop over subsets, belief, plausibility and pignistic
// probability by their definitions. evidence_test.cpp checks sensing/evidence.hpp against it, and
// pseiki/hierarchical_evidence_test.cpp the hierarchical rule.
#pragma once

#include <bit>
#include <cstddef>
#include <vector>

#include "spar/sensing/evidence.hpp"

namespace spar::sensing {

using Dense = std::vector<double>;  // Dense[mask] = m(mask), mask 0 = the empty set

inline Dense dense(const MassFunction& m) {
  Dense out(std::size_t{1} << m.frame_size(), 0.0);
  for (const FocalElement& element : m.elements()) {
    unsigned mask = 0;
    for (const int x : element.set.members()) mask |= 1U << x;
    out[mask] = element.mass;
  }
  return out;
}

inline FocalSet set_of(unsigned mask, int n) {
  FocalSet set(n);
  for (int x = 0; x < n; ++x)
    if (mask & (1U << x)) set.insert(x);
  return set;
}

struct DenseCombination {
  Dense mass;
  double conflict{0};
};

inline DenseCombination brute_dempster(const Dense& a, const Dense& b) {
  Dense joint(a.size(), 0.0);
  for (unsigned x = 1; x < a.size(); ++x)
    for (unsigned y = 1; y < b.size(); ++y) joint[x & y] += a[x] * b[y];
  DenseCombination out{Dense(a.size(), 0.0), joint[0]};
  for (unsigned z = 1; z < a.size(); ++z) out.mass[z] = joint[z] / (1 - joint[0]);
  return out;
}

inline double brute_belief(const Dense& m, unsigned set) {
  double total = 0;
  for (unsigned b = 1; b < m.size(); ++b)
    if ((b & ~set) == 0) total += m[b];
  return total;
}

inline double brute_plausibility(const Dense& m, unsigned set) {
  double total = 0;
  for (unsigned b = 1; b < m.size(); ++b)
    if (b & set) total += m[b];
  return total;
}

inline double brute_pignistic(const Dense& m, int x) {
  double total = 0;
  for (unsigned b = 1; b < m.size(); ++b)
    if (b & (1U << x)) total += m[b] / std::popcount(b);
  return total;
}

}  // namespace spar::sensing
