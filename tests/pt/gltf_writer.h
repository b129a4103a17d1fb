// Test helper: writes small glTF 2.0 scenes (one data-URI buffer) so render tests load
// known geometry, materials, lights and cameras through the real loader.
#pragma once
#include <stb/stb_image_write.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace osr::test {

class GltfWriter {
 public:
  using json = nlohmann::json;

  // Adds a material (glTF JSON object); returns its index.
  int material(json m) {
    materials_.push_back(std::move(m));
    return int(materials_.size()) - 1;
  }
  // Adds a mesh node of triangles (positions per vertex, counter-clockwise = front).
  void mesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices, int mat,
            const std::vector<glm::vec2>& uvs = {}) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (auto p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    size_t posOffset = append(positions.data(), positions.size() * 12);
    size_t idxOffset = append(indices.data(), indices.size() * 4);
    int posView = view(posOffset, positions.size() * 12),
        idxView = view(idxOffset, indices.size() * 4);
    accessors_.push_back({{"bufferView", posView},
                          {"componentType", 5126},
                          {"count", positions.size()},
                          {"type", "VEC3"},
                          {"min", {lo.x, lo.y, lo.z}},
                          {"max", {hi.x, hi.y, hi.z}}});
    accessors_.push_back({{"bufferView", idxView},
                          {"componentType", 5125},
                          {"count", indices.size()},
                          {"type", "SCALAR"}});
    int a = int(accessors_.size());
    json attributes = {{"POSITION", a - 2}};
    if (!uvs.empty()) {
      int uvView = view(append(uvs.data(), uvs.size() * 8), uvs.size() * 8);
      accessors_.push_back({{"bufferView", uvView},
                            {"componentType", 5126},
                            {"count", uvs.size()},
                            {"type", "VEC2"}});
      attributes["TEXCOORD_0"] = int(accessors_.size()) - 1;
    }
    meshes_.push_back(
        {{"primitives", {{{"attributes", attributes}, {"indices", a - 1}, {"material", mat}}}}});
    nodes_.push_back({{"mesh", int(meshes_.size()) - 1}});
  }
  // COLOR_0 (float RGBA) or TEXCOORD_1 for the last mesh's vertices.
  void vertexColors(const std::vector<glm::vec4>& colors) {
    attribute("COLOR_0", colors.data(), colors.size(), 16, "VEC4");
  }
  void texCoords1(const std::vector<glm::vec2>& uvs) {
    attribute("TEXCOORD_1", uvs.data(), uvs.size(), 8, "VEC2");
  }
  // A quad p0, p1, p2, p3 (counter-clockwise seen from the front).
  // uv (0,0), (1,0), (1,1), (0,1) at p0..p3.
  void quad(glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, int mat) {
    mesh({p0, p1, p2, p3}, {0, 1, 2, 0, 2, 3}, mat, {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  }
  // An RGBA8 texture (PNG data URI, clamp-to-edge); returns its texture index.
  int texture(int w, int h, const std::vector<uint8_t>& rgba) {
    std::vector<uint8_t> png;
    stbi_write_png_to_func(
        [](void* ctx, void* data, int size) {
          auto* out = static_cast<std::vector<uint8_t>*>(ctx);
          out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
        },
        &png, w, h, 4, rgba.data(), w * 4);
    images_.push_back({{"uri", "data:image/png;base64," + base64(png)}});
    samplers_.push_back({{"wrapS", 33071}, {"wrapT", 33071}});
    textures_.push_back(
        {{"source", int(images_.size()) - 1}, {"sampler", int(samplers_.size()) - 1}});
    return int(textures_.size()) - 1;
  }
  // A surface of revolution about the +Y axis through `c`: the profile's points (radius from
  // the axis, height), turned in `segments` steps. Its triangles face the side the profile's
  // left-hand normal (-dy, dr) points to: outward for a profile that runs from top to bottom
  // on the far side of the axis. Triangles at radius 0 that would collapse are left out.
  void revolve(glm::vec3 c, const std::vector<glm::vec2>& profile, int mat, int segments = 48) {
    std::vector<glm::vec3> p;
    std::vector<uint32_t> idx;
    const int rows = int(profile.size());
    for (const glm::vec2& q : profile)
      for (int j = 0; j <= segments; ++j) {
        float ph = 2 * float(M_PI) * j / segments;
        p.push_back(c + glm::vec3(q.x * std::cos(ph), q.y, q.x * std::sin(ph)));
      }
    for (int i = 0; i + 1 < rows; ++i)
      for (int j = 0; j < segments; ++j) {
        uint32_t a = i * (segments + 1) + j, b = a + segments + 1;
        if (profile[i].x != 0.f) idx.insert(idx.end(), {a, a + 1, b});
        if (profile[i + 1].x != 0.f) idx.insert(idx.end(), {a + 1, b + 1, b});
      }
    mesh(p, idx, mat);
  }
  // A UV sphere with outward-facing triangles (inward: the inside of a closed room).
  void sphere(glm::vec3 c, float r, int mat, int rings = 24, int segments = 48,
              bool inward = false) {
    std::vector<glm::vec2> profile;
    for (int i = 0; i <= rings; ++i) {
      float th = float(M_PI) * (inward ? rings - i : i) / rings;
      // Exactly 0 at the poles (sin(pi) is not, in float).
      profile.push_back({i == 0 || i == rings ? 0.f : r * std::sin(th), r * std::cos(th)});
    }
    revolve(c, profile, mat, segments);
  }
  // A closed cylinder of radius r from y = c.y to c.y + h.
  void cylinder(glm::vec3 c, float r, float h, int mat, int segments = 48) {
    revolve(c, {{0.f, h}, {r, h}, {r, 0.f}, {0.f, 0.f}}, mat, segments);
  }
  // A torus about the +Y axis through c: ring radius R, tube radius r.
  void torus(glm::vec3 c, float R, float r, int mat, int rings = 24, int segments = 48) {
    std::vector<glm::vec2> profile;
    for (int i = 0; i <= rings; ++i) {
      float ph = 2 * float(M_PI) * i / rings;
      profile.push_back({R + r * std::sin(ph), r * std::cos(ph)});
    }
    revolve(c, profile, mat, segments);
  }
  void light(json l) {
    lights_.push_back(l);
    json node = {{"extensions", {{"KHR_lights_punctual", {{"light", lights_.size() - 1}}}}}};
    if (l.contains("_translation")) node["translation"] = l["_translation"];
    if (l.contains("_rotation")) node["rotation"] = l["_rotation"];
    lights_.back().erase("_translation");
    lights_.back().erase("_rotation");
    nodes_.push_back(node);
  }
  // A perspective camera at `eye` looking at `target` (+Y up), aspect 1.
  void camera(glm::vec3 eye, glm::vec3 target, float yfov) {
    glm::vec3 back = glm::normalize(eye - target);
    glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
    glm::vec3 up = glm::cross(back, right);
    glm::mat3 m(right, up, back);
    glm::quat q = glm::quat_cast(m);
    cameras_.push_back({{"type", "perspective"},
                        {"perspective", {{"yfov", yfov}, {"aspectRatio", 1.0}, {"znear", 0.01}}}});
    nodes_.push_back({{"camera", int(cameras_.size()) - 1},
                      {"translation", {eye.x, eye.y, eye.z}},
                      {"rotation", {q.x, q.y, q.z, q.w}}});
  }
  void write(const std::string& path) const {
    json g;
    g["asset"] = {{"version", "2.0"}};
    g["extensionsUsed"] = {"KHR_materials_specular", "KHR_materials_ior",
                           "KHR_materials_transmission", "KHR_materials_emissive_strength",
                           "KHR_lights_punctual"};
    g["buffers"] = {{{"byteLength", data_.size()},
                     {"uri", "data:application/octet-stream;base64," + base64(data_)}}};
    g["bufferViews"] = views_;
    g["accessors"] = accessors_;
    g["materials"] = materials_;
    g["meshes"] = meshes_;
    g["nodes"] = nodes_;
    if (!cameras_.empty()) g["cameras"] = cameras_;
    if (!textures_.empty()) {
      g["images"] = images_;
      g["samplers"] = samplers_;
      g["textures"] = textures_;
    }
    if (!lights_.empty()) g["extensions"] = {{"KHR_lights_punctual", {{"lights", lights_}}}};
    std::vector<int> all;
    for (size_t i = 0; i < nodes_.size(); ++i) all.push_back(int(i));
    g["scenes"] = {{{"nodes", all}}};
    g["scene"] = 0;
    std::ofstream(path) << g.dump();
  }

  // An RGBA8 texture like texture(), sampled nearest (texel edges stay sharp).
  int nearestTexture(int w, int h, const std::vector<uint8_t>& rgba) {
    int t = texture(w, h, rgba);
    samplers_.back()["magFilter"] = 9728;  // NEAREST
    return t;
  }

  // Lambertian as Blender's exporter writes it: specular colour 0, roughness 1.
  static json diffuse(glm::vec3 c) {
    return {{"pbrMetallicRoughness",
             {{"baseColorFactor", {c.x, c.y, c.z, 1.0}}, {"metallicFactor", 0.0}}},
            {"doubleSided", true},
            {"extensions", {{"KHR_materials_specular", {{"specularColorFactor", {0, 0, 0}}}}}}};
  }
  static json emitter(glm::vec3 radiance, bool doubleSided) {
    float s = std::max(radiance.x, std::max(radiance.y, radiance.z));
    return {
        {"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1.0}}, {"metallicFactor", 0.0}}},
        {"emissiveFactor", {radiance.x / s, radiance.y / s, radiance.z / s}},
        {"doubleSided", doubleSided},
        {"extensions",
         {{"KHR_materials_emissive_strength", {{"emissiveStrength", s}}},
          {"KHR_materials_specular", {{"specularColorFactor", {0, 0, 0}}}}}}};
  }
  static json glass(float ior) {
    return {
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {1, 1, 1, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.0}}},
        {"doubleSided", true},
        {"extensions",
         {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
          {"KHR_materials_ior", {{"ior", ior}}}}}};
  }

 private:
  void attribute(const char* name, const void* data, size_t count, size_t bytes, const char* type) {
    int v = view(append(data, count * bytes), count * bytes);
    accessors_.push_back(
        {{"bufferView", v}, {"componentType", 5126}, {"count", count}, {"type", type}});
    meshes_.back()["primitives"][0]["attributes"][name] = int(accessors_.size()) - 1;
  }
  size_t append(const void* p, size_t bytes) {
    size_t off = data_.size();
    data_.resize(off + bytes);
    std::memcpy(data_.data() + off, p, bytes);
    return off;
  }
  int view(size_t offset, size_t bytes) {
    views_.push_back({{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}});
    return int(views_.size()) - 1;
  }
  static std::string base64(const std::vector<uint8_t>& d) {
    static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < d.size(); i += 3) {
      uint32_t v =
          d[i] << 16 | (i + 1 < d.size() ? d[i + 1] << 8 : 0) | (i + 2 < d.size() ? d[i + 2] : 0);
      out += k[v >> 18 & 63];
      out += k[v >> 12 & 63];
      out += i + 1 < d.size() ? k[v >> 6 & 63] : '=';
      out += i + 2 < d.size() ? k[v & 63] : '=';
    }
    return out;
  }

  std::vector<uint8_t> data_;
  json views_ = json::array(), accessors_ = json::array(), materials_ = json::array(),
       meshes_ = json::array(), nodes_ = json::array(), cameras_ = json::array(),
       lights_ = json::array(), images_ = json::array(), samplers_ = json::array(),
       textures_ = json::array();
};

// Stochastic transparency, analytically: a red diffuse ground (albedo 0.5) under a green
// diffuse quad (albedo 0.5) at y = 1 whose alpha texture is 0.75 left of u = 0.5 and 0.25
// right of it, a sun straight down of irradiance 2, a camera looking down at the quad.
// Blended, a pixel's green is alpha x 2 x 0.5 / pi (the quad's top, met with probability
// alpha) and its red (1 - alpha)^2 x 2 x 0.5 / pi (the ground, seen through the quad and lit
// through it); no other light reaches the camera (the quad reflects no red, the ground no
// green). `alphaMode` is the quad's glTF alphaMode.
inline void writeCoverageScene(const std::string& path, const std::string& alphaMode) {
  GltfWriter g;
  int ground = g.material(GltfWriter::diffuse({0.5f, 0.f, 0.f}));
  auto quad = GltfWriter::diffuse({0.f, 0.5f, 0.f});
  quad["pbrMetallicRoughness"]["baseColorTexture"] = {
      {"index", g.nearestTexture(2, 1, {255, 255, 255, 191, 255, 255, 255, 64})}};
  quad["alphaMode"] = alphaMode;
  int quadMat = g.material(quad);
  g.quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, ground);
  g.quad({-2, 1, 2}, {2, 1, 2}, {2, 1, -2}, {-2, 1, -2}, quadMat);  // u along +x, facing up
  g.light({{"type", "directional"},
           {"intensity", 683.0 * 2.0},
           {"_rotation", {-std::sin(M_PI / 4), 0, 0, std::cos(M_PI / 4)}}});
  g.camera({0.f, 3.f, 0.001f}, {0.f, 0.f, 0.f}, 0.5f);
  g.write(path);
}

}  // namespace osr::test
