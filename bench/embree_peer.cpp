#ifdef OSR_HAVE_EMBREE
#include "bench/embree_peer.h"

#include <embree3/rtcore_builder.h>

#include <algorithm>
#include <chrono>
#include <new>
#include <string>
#include <thread>

#include "bvh/aabb.h"
#include "common/error.h"
#include "shaders/shared/bvh.h"

namespace osr::bench {

namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// Nodes of the binary tree rtcBuildBVH builds through our callbacks.
struct PeerNode {
  bool leaf = false;
  unsigned count = 0;        // leaf: primitives
  RTCBounds bounds[2] = {};  // interior: child bounds
  PeerNode* children[2] = {};
};

float area(const RTCBounds& b) {
  float dx = b.upper_x - b.lower_x, dy = b.upper_y - b.lower_y, dz = b.upper_z - b.lower_z;
  return 2.0f * (dx * dy + dy * dz + dz * dx);
}

RTCBounds merge(const RTCBounds& a, const RTCBounds& b) {
  RTCBounds m{};
  m.lower_x = std::min(a.lower_x, b.lower_x);
  m.lower_y = std::min(a.lower_y, b.lower_y);
  m.lower_z = std::min(a.lower_z, b.lower_z);
  m.upper_x = std::max(a.upper_x, b.upper_x);
  m.upper_y = std::max(a.upper_y, b.upper_y);
  m.upper_z = std::max(a.upper_z, b.upper_z);
  return m;
}

// Sum of node and leaf terms of our SAH below `n`, whose own box is `box`.
double sahSum(const PeerNode* n, const RTCBounds& box, unsigned depth, unsigned& maxDepth) {
  if (n->leaf) return double(gpu::bvh::kSahTriangleCost) * area(box) * n->count;
  maxDepth = std::max(maxDepth, depth);
  double sum = double(gpu::bvh::kSahNodeCost) * area(box);
  for (int i = 0; i < 2; ++i) sum += sahSum(n->children[i], n->bounds[i], depth + 1, maxDepth);
  return sum;
}

// Embree calls this from C code, so it records the first error instead of throwing.
void errorHandler(void* user, RTCError code, const char* message) {
  auto* error = static_cast<std::string*>(user);
  if (error->empty()) *error = "embree: error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

}  // namespace

EmbreePeer::EmbreePeer(const bvh::SyntheticMesh& mesh, unsigned threads) : mesh_(mesh), threads_(threads) {
  std::string config = "threads=" + std::to_string(threads);
  device_ = rtcNewDevice(config.c_str());
  if (!device_) throw DeviceError("embree: rtcNewDevice failed");
  rtcSetDeviceErrorFunction(device_, errorHandler, &error_);
}

EmbreePeer::~EmbreePeer() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

double EmbreePeer::buildScene() {
  if (scene_) rtcReleaseScene(scene_);
  auto start = std::chrono::steady_clock::now();
  scene_ = rtcNewScene(device_);
  RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  // Shared buffers straight from our Vertex (stride 32) and Triangle (stride 16) arrays.
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, mesh_.vertices.data(), 0,
                             sizeof(gpu::scene::Vertex), mesh_.vertices.size());
  rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh_.triangles.data(), 0,
                             sizeof(gpu::scene::Triangle), mesh_.triangles.size());
  rtcCommitGeometry(geom);
  rtcAttachGeometry(scene_, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(scene_);
  double ms = msSince(start);
  if (!error_.empty()) throw DeviceError(error_);
  return ms;
}

EmbreePeer::BinaryBvh EmbreePeer::buildBinaryBvh() const {
  std::vector<RTCBuildPrimitive> prims(mesh_.triangles.size());
  for (size_t i = 0; i < prims.size(); ++i) {
    bvh::Aabb b;
    const auto& t = mesh_.triangles[i];
    for (uint32_t v : {t.v0, t.v1, t.v2}) b.grow(mesh_.vertices[v].position);
    prims[i] = {b.lo.x, b.lo.y, b.lo.z, 0u, b.hi.x, b.hi.y, b.hi.z, uint32_t(i)};
  }
  RTCBVH handle = rtcNewBVH(device_);
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_MEDIUM;
  args.maxBranchingFactor = 2;
  args.maxDepth = gpu::bvh::kBvhMaxDepth;
  args.maxLeafSize = gpu::bvh::kBvhMaxLeafTriangles;
  args.traversalCost = gpu::bvh::kSahNodeCost;
  args.intersectionCost = gpu::bvh::kSahTriangleCost;
  args.bvh = handle;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = [](RTCThreadLocalAllocator alloc, unsigned, void*) -> void* {
    return new (rtcThreadLocalAlloc(alloc, sizeof(PeerNode), 16)) PeerNode;
  };
  args.setNodeChildren = [](void* node, void** children, unsigned count, void*) {
    for (unsigned i = 0; i < count; ++i) static_cast<PeerNode*>(node)->children[i] = static_cast<PeerNode*>(children[i]);
  };
  args.setNodeBounds = [](void* node, const RTCBounds** bounds, unsigned count, void*) {
    for (unsigned i = 0; i < count; ++i) static_cast<PeerNode*>(node)->bounds[i] = *bounds[i];
  };
  args.createLeaf = [](RTCThreadLocalAllocator alloc, const RTCBuildPrimitive*, size_t count, void*) -> void* {
    PeerNode* leaf = new (rtcThreadLocalAlloc(alloc, sizeof(PeerNode), 16)) PeerNode;
    leaf->leaf = true;
    leaf->count = unsigned(count);
    return leaf;
  };
  // The builder overwrites the primitive array; its box is the union of the input boxes.
  RTCBounds rootBox = {prims[0].lower_x, prims[0].lower_y, prims[0].lower_z, 0,
                       prims[0].upper_x, prims[0].upper_y, prims[0].upper_z, 0};
  for (const auto& p : prims)
    rootBox = merge(rootBox, RTCBounds{p.lower_x, p.lower_y, p.lower_z, 0, p.upper_x, p.upper_y, p.upper_z, 0});
  auto start = std::chrono::steady_clock::now();
  auto* root = static_cast<PeerNode*>(rtcBuildBVH(&args));
  BinaryBvh out;
  out.ms = msSince(start);
  if (!root || !error_.empty()) throw DeviceError(error_.empty() ? "embree: rtcBuildBVH failed" : error_);
  unsigned depth = 0;
  // A root leaf still costs one node in our convention (traversal always starts at a node).
  double sum = sahSum(root, rootBox, 1, depth) + (root->leaf ? gpu::bvh::kSahNodeCost * area(rootBox) : 0.0);
  out.sah = sum / area(rootBox);
  out.depth = std::max(depth, 1u);
  rtcReleaseBVH(handle);
  return out;
}

double EmbreePeer::trace(const std::vector<gpu::bvh_trace::TraceRay>& rays,
                         std::vector<gpu::bvh_trace::TraceHit>& hits) const {
  hits.resize(rays.size());
  auto work = [&](size_t begin, size_t end) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for (size_t i = begin; i < end; ++i) {
      const auto& r = rays[i];
      RTCRayHit rh{};
      rh.ray.org_x = r.origin.x;
      rh.ray.org_y = r.origin.y;
      rh.ray.org_z = r.origin.z;
      rh.ray.dir_x = r.dir.x;
      rh.ray.dir_y = r.dir.y;
      rh.ray.dir_z = r.dir.z;
      rh.ray.tnear = r.tMin;
      rh.ray.tfar = r.tMax;
      rh.ray.mask = 0xffffffffu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &rh);
      bool found = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      hits[i] = {rh.ray.tfar, found ? rh.hit.primID : gpu::bvh_trace::kNoHit, glm::vec2(rh.hit.u, rh.hit.v)};
    }
  };
  auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  size_t per = (rays.size() + threads_ - 1) / threads_;
  for (unsigned t = 0; t < threads_; ++t)
    pool.emplace_back(work, std::min(rays.size(), t * per), std::min(rays.size(), (t + 1) * per));
  for (auto& th : pool) th.join();
  return msSince(start);
}

}  // namespace osr::bench
#endif
