// Shared fixture for every test: one Vulkan context with the Khronos validation layer on.
// test_main.cpp fails any test during which a validation message was reported.
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "vk/context.h"

namespace osr::test {

// The process-wide test context (validation on). Created on first use.
vk::Context& context();

// Path of a file under tests/data.
std::string dataPath(const std::string& name);
// A fresh-or-existing scratch folder under the system temp dir, unique to this process and
// `tag` (the test file's name), so parallel CTest runs never share one.
std::filesystem::path tempDir(const std::string& tag);

// Path of a reference scene file, e.g. referencePath("cornell/cornell.gltf").
std::string referencePath(const std::string& name);

}  // namespace osr::test
