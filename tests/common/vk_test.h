// Shared fixture for every test: one Vulkan context with the Khronos validation layer on.
// test_main.cpp fails any test during which a validation message was reported.
#pragma once
#include <gtest/gtest.h>

#include "vk/context.h"

namespace osr::test {

// The process-wide test context (validation on). Created on first use.
vk::Context& context();

// Path of a file under tests/data.
std::string dataPath(const std::string& name);
// Path of a reference scene file, e.g. referencePath("cornell/cornell.gltf").
std::string referencePath(const std::string& name);

}  // namespace osr::test
