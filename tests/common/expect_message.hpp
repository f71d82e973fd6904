// EXPECT_THROW_MESSAGE(statement, fragment): `statement` throws a spar::Error (any module's error
// type: every one derives from it, common/error.hpp) whose message contains `fragment`. STYLE.md:
// tests check the message, not just the type. Anything else thrown, or nothing, is a failure that
// says what happened. The one helper for every test folder.
//
// Example:
//   EXPECT_THROW_MESSAGE(parse(pool, "x +"), "expected an operand");
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <string>

#include "spar/common/error.hpp"

#define EXPECT_THROW_MESSAGE(statement, fragment)                                  \
  do {                                                                             \
    try {                                                                          \
      (void)(statement);                                                           \
      ADD_FAILURE() << "expected a spar::Error containing '" << (fragment) << "'"; \
    } catch (const ::spar::Error& spar_error) {                                    \
      EXPECT_NE(std::string(spar_error.what()).find(fragment), std::string::npos)  \
          << spar_error.what();                                                    \
    } catch (const std::exception& other_error) {                                  \
      ADD_FAILURE() << "expected a spar::Error containing '" << (fragment)         \
                    << "', got another exception: " << other_error.what();         \
    }                                                                              \
  } while (false)
