// Fuzz target: the expression parser and printer (symbolic/parse.hpp).
// Property: any text either parses or throws spar::Error; what parses prints as text that
// re-parses to the same node (hash-consed: the same id). Anything else -- a crash, a sanitizer
// report, another exception, a broken round trip -- aborts, which libFuzzer reports.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "spar/common/error.hpp"
#include "spar/symbolic/parse.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  spar::symbolic::ExprPool pool;
  spar::symbolic::Expr parsed;
  try {
    parsed = spar::symbolic::parse(pool, text);
  } catch (const spar::Error&) {
    return 0;  // a clear refusal is a correct answer
  }
  std::string printed;
  try {
    printed = spar::symbolic::to_string(parsed, 1e5);
  } catch (const spar::Error&) {
    return 0;  // too large as a tree: refused by design
  }
  const spar::symbolic::Expr again = spar::symbolic::parse(pool, printed);
  if (again != parsed) {
    std::fprintf(stderr, "round trip changed the expression:\n  printed: %s\n  again:   %s\n",
                 printed.c_str(), spar::symbolic::to_string(again, 1e5).c_str());
    std::abort();
  }
  return 0;
}
