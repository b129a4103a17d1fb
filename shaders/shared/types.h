// Maps GLSL types onto GLM so that a struct written once here is seen by both C++ and GLSL.
// Layout rules (std430): scalars, vec2 and vec4 aligned to their size; a vec3 only when a
// scalar follows it; padding written out. tests/vk/test_shared_layout.cpp checks sizes.
#ifndef OSR_SHARED_TYPES_H
#define OSR_SHARED_TYPES_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace osr::gpu {
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using ivec2 = glm::ivec2;
using ivec4 = glm::ivec4;
using uvec2 = glm::uvec2;
using uvec3 = glm::uvec3;
using uvec4 = glm::uvec4;
using mat3 = glm::mat3;
using mat4 = glm::mat4;
using uint = uint32_t;
}  // namespace osr::gpu
#define OSR_NAMESPACE_BEGIN(name) namespace osr::gpu::name {
#define OSR_NAMESPACE_END }
#define OSR_CONST(type, name, value) inline constexpr type name = value
#else
#define OSR_NAMESPACE_BEGIN(name)
#define OSR_NAMESPACE_END
#define OSR_CONST(type, name, value) const type name = value
#endif

#endif
