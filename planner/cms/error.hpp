// CmsError: a request the constraint manipulation system cannot honour because it is malformed
// (an unknown step or variable id, a label outside its domain, an allowed-pair matrix of the
// wrong shape, codesignating variables of different domains). A constraint that merely makes the
// plan inconsistent is not an error: the operation returns false or Consistency::kInconsistent.
#pragma once

#include "spar/common/error.hpp"

namespace spar::planner::cms {

class CmsError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::planner::cms
