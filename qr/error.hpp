// qr::QrError: a user's or a file's mistake in the qr module (a bad sign character, a malformed
// network, a bad option value). Derives from spar::Error (common/error.hpp), like every module's
// error.
//
// Example:
//   try {
//     const Sign value = sign_from_char('x');
//   } catch (const QrError& error) {
//     std::cerr << error.what() << '\n';   // "not a qualitative value: 'x' (expected + 0 - ?)"
//   }
#pragma once

#include "spar/common/error.hpp"

namespace spar::qr {

class QrError : public spar::Error {
 public:
  using spar::Error::Error;
};

}  // namespace spar::qr
