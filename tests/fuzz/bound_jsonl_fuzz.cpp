// Fuzz target: `spar bound --jsonl`'s record reader (cli/bound_json.hpp).
// Property: every line of any input gives one JSON object -- a result or an error record -- that
// can be written out; nothing throws, crashes or trips a sanitizer. A small box budget keeps each
// bound cheap so the fuzzer explores the reader, not the bounding.
#include <cstdint>
#include <sstream>
#include <string>
#include <string_view>

#include "cli/bound_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream lines(std::string(reinterpret_cast<const char*>(data), size));
  spar::bounds::BoundOptions options;
  options.max_box_evaluations = 2'000;
  std::string line;
  for (std::size_t number = 1; std::getline(lines, line); ++number) {
    bool ok = true;
    const nlohmann::ordered_json result = spar::cli::bound_record(line, number, options, ok);
    (void)result.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  }
  return 0;
}
