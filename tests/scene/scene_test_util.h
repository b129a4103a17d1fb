// Helpers shared by the tests of src/scene.
#pragma once
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "common/error.h"
#include "scene/scene.h"

namespace osr::test {

inline void expectNear(glm::vec3 a, glm::vec3 b, float tol = 1e-5f) {
  EXPECT_LE(glm::length(a - b), tol) << "(" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x
                                     << ", " << b.y << ", " << b.z << ")";
}

inline bool hasWarning(const scene::Scene& s, const std::string& part) {
  for (const auto& w : s.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

// `load(path)` must throw an InputError of one line that starts "<path>: " and contains `part`.
inline void expectInputError(const std::function<void(const std::string&)>& load,
                             const std::string& path, const std::string& part) {
  try {
    load(path);
    ADD_FAILURE() << path << ": accepted, expected an InputError containing '" << part << "'";
  } catch (const InputError& e) {
    std::string msg = e.what();
    EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

}  // namespace osr::test
