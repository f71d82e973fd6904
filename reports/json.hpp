// The JSON back end of the report model (reports/model.hpp): the source of truth of every report
// spar writes, schema "spar-report/1", documented field by field in docs/report-schema.md with the
// JSON Schema the tests validate against. Written and read from the records' `fields` lists, so a
// field added to a record is written and read back with no change here.
//
// Writing: members in `fields` order; an empty std::optional is left out, an empty Nullable is
// null; doubles that JSON cannot hold are the strings "inf", "-inf", "nan".
// Reading (a report from disk, to render it again): the "schema" member must say spar-report/1;
// a missing required member or one of the wrong type is a ReportError naming its path
// ("malformed report: chosen.steps[2].action: missing"); unknown members are ignored.
//
// Example:
//   const nlohmann::ordered_json document = to_json(build_report(result));
//   std::ofstream("report.json") << document.dump(2) << '\n';
//   const Report again = report_from_json(document);   // renders to the same Markdown
#pragma once

#include <nlohmann/json.hpp>

#include "spar/reports/model.hpp"

namespace spar::reports {

[[nodiscard]] nlohmann::ordered_json to_json(const Report& report);
[[nodiscard]] nlohmann::ordered_json to_json(const Chosen& chosen);
[[nodiscard]] nlohmann::ordered_json to_json(const BoundRecord& record);
[[nodiscard]] nlohmann::ordered_json to_json(const SensePlanRecord& record);

// Throws ReportError: "not a spar-report/1 report (...)" or "malformed report: <path>: <what>".
[[nodiscard]] Report report_from_json(const nlohmann::ordered_json& document);
// Throws ReportError "malformed bound record: <path>: <what>".
[[nodiscard]] BoundRecord bound_record_from_json(const nlohmann::ordered_json& document);

}  // namespace spar::reports
