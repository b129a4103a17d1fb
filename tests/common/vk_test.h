// Shared fixture for every device test: one Vulkan context with the Khronos validation layer on.
// test_main.cpp fails any test during which a validation message was reported.
#pragma once
#include <gtest/gtest.h>

#include "common/test_paths.h"
#include "vk/context.h"

namespace osr::test {

// The process-wide test context (validation on). Created on first use.
vk::Context& context();

}  // namespace osr::test
