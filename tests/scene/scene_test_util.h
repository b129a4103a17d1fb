// Helpers shared by the tests of src/scene and src/scene_gpu.
#pragma once
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "common/error.h"
#include "scene/environment.h"
#include "scene/scene.h"

namespace osr::test {

// 16 x 8 map: a smooth gradient plus one bright texel, so sampling has something to find.
inline scene::Environment testEnvironment() {
  scene::Environment env;
  env.width = 16;
  env.height = 8;
  for (uint32_t y = 0; y < env.height; ++y)
    for (uint32_t x = 0; x < env.width; ++x)
      env.texels.push_back(glm::vec4(0.1f + 0.05f * x, 0.2f + 0.1f * y, 0.5f, 1.0f));
  env.texels[3 * 16 + 5] = glm::vec4(40.0f, 30.0f, 20.0f, 1.0f);
  return env;
}


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
