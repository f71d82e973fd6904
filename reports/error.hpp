// The report layer's error: a report that cannot be rendered (a JSON document that is not a
// spar-report/1), an unknown output format, or a report folder that cannot be written.
#pragma once

#include "spar/common/error.hpp"

namespace spar::reports {

class ReportError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::reports
