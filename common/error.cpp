#include "spar/common/error.hpp"

namespace spar {

// Out of line so the vtable and type_info live in one object file.
Error::~Error() = default;

}  // namespace spar
