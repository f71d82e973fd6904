// EXPECT_THROW_MESSAGE(statement, fragment): the statement throws KinematicsError whose message
// contains `fragment` (STYLE.md: tests check the message, not just the type).
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "kinematics/dh.hpp"

#define EXPECT_THROW_MESSAGE(statement, fragment)                                           \
  try {                                                                                     \
    (void)(statement);                                                                      \
    ADD_FAILURE() << "expected KinematicsError containing '" << (fragment) << "'";          \
  } catch (const ::spar::kinematics::KinematicsError& error) {                              \
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what(); \
  }
