// Tests of the option checks: validate(options) must throw std::invalid_argument whose message names the
// parameter (and its value), e.g. "panels/window = 4".
#pragma once

#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace ardsim_pose {

template <typename Options>
void expectRefused(const Options& options, const std::string& named) {
  try {
    validate(options);
    ADD_FAILURE() << "accepted; expected an error naming " << named;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
  }
}

}  // namespace ardsim_pose
