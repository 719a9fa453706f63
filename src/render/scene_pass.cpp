// The DrawList pipelines of the renderer: instanced meshes lit by the
// list's lights (the first sun casting a shadow map fitted to the list's
// bounds), a sky gradient, sprites with alpha or additive blending, and
// lines. Meshes are uploaded once and kept while the list shares them (the
// cache holds a reference); per-instance data is uploaded each frame.
#include <GL/glew.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "render/gl_program.h"
#include "render/renderer.h"

namespace sylva::render {

namespace {

// The vertex attribute of sub-pixel coverage (scene.vert, scene_shadow.vert;
// 3..7 hold the instance's model matrix and tint).
constexpr GLuint kCoverageLocation = 8;

// What a mesh still has to upload (Renderer::Stage: in slices over several
// frames): the CPU-side arrays made for the GPU and, part by part, the
// bytes already sent.
struct Staging {
  std::vector<mesh::Vec3f> colors;
  std::vector<uint32_t> sorted;  // indices, opaque triangles first (with partial coverage)
  struct Part {
    GLuint buffer;
    const void* data;
    size_t bytes;
  };
  std::vector<Part> parts;
  size_t part = 0, offset = 0;  // the next byte to send
};

struct GpuMesh {
  std::shared_ptr<const mesh::TriangleMesh> mesh;  // keeps the key alive
  mesh::Palette palette;
  GLuint vao = 0, buffers[3] = {0, 0, 0}, index = 0, instances = 0, coverage = 0;
  GLsizei indexCount = 0;
  GLsizei opaqueCount = 0;  // indices [opaqueCount, indexCount): partial coverage, blended last
  bool used = false;
  std::unique_ptr<Staging> staging;  // set while parts are still to upload
};

void DeleteMesh(GpuMesh& m) {
  glDeleteBuffers(3, m.buffers);
  glDeleteBuffers(1, &m.index);
  glDeleteBuffers(1, &m.instances);
  glDeleteBuffers(1, &m.coverage);
  glDeleteVertexArrays(1, &m.vao);
}

// Instance layout: a 4x4 matrix (columns at locations 3..6) and a tint (7).
struct GpuInstance {
  float model[16];
  float tint[3];
};
static_assert(sizeof(GpuInstance) == 76, "instance layout");

// Renderer::Stage draws the next list's shadow map in this many bands of
// rows, one a call (a frame of the viewer).
constexpr int kShadowBands = 4;

// FNV-1a over bytes, continuing from `h`.
constexpr uint64_t kFnvBasis = 1469598103934665603ull;
uint64_t Fnv(uint64_t h, const void* data, size_t n) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}

}  // namespace

struct Renderer::ScenePass {
  GLuint meshProgram = 0, shadowProgram = 0, skyProgram = 0, spriteProgram = 0, lineProgram = 0;
  GLint viewProj = -1, eye = -1, lightCount = -1, lightType = -1, lightVector = -1, lightColor = -1,
        shadowLight = -1, lightViewProj = -1, shadowMap = -1, wire = -1;
  GLint shadowViewProj = -1;
  GLint skyInverse = -1, skyTop = -1, skyHorizon = -1;
  GLint spriteViewProj = -1, spriteScale = -1, lineViewProj = -1;
  GLuint shadowFbo = 0, shadowDepth = 0, emptyVao = 0;
  // The next list's shadow map, drawn by Stage() a band a frame: spareBands
  // of kShadowBands done for spareKey (-1: nothing), swapped in by Draw.
  GLuint spareFbo = 0, spareDepth = 0;
  uint64_t spareKey = 0;
  int spareBands = -1;
  int shadowSize = 0;      // texels on a side of the depth texture allocated
  uint64_t shadowKey = 0;  // what the shadow map shows (see Draw)
  bool shadowValid = false;
  std::unordered_map<const mesh::TriangleMesh*, GpuMesh> meshes;
  // The meshes of the last Stage() list: kept while another list is drawn.
  std::unordered_set<const mesh::TriangleMesh*> staged;
  GLuint spriteVao = 0, spriteBuffers[4] = {0, 0, 0, 0};
  GLuint lineVao = 0, lineBuffers[2] = {0, 0};

  ~ScenePass() {
    for (auto& [k, m] : meshes) DeleteMesh(m);
    for (GLuint p : {meshProgram, shadowProgram, skyProgram, spriteProgram, lineProgram})
      glDeleteProgram(p);
    glDeleteFramebuffers(1, &shadowFbo);
    glDeleteTextures(1, &shadowDepth);
    glDeleteFramebuffers(1, &spareFbo);
    glDeleteTextures(1, &spareDepth);
    glDeleteVertexArrays(1, &emptyVao);
    glDeleteVertexArrays(1, &spriteVao);
    glDeleteBuffers(4, spriteBuffers);
    glDeleteVertexArrays(1, &lineVao);
    glDeleteBuffers(2, lineBuffers);
  }

  Status Init(const std::string& dir) {
    auto program = [&](const char* vert, const char* frag, GLuint& out) -> Status {
      auto p = CompileProgram(dir, vert, frag);
      if (!p) return p.error();
      out = *p;
      return {};
    };
    if (Status s = program("scene.vert", "scene.frag", meshProgram); !s.ok()) return s;
    if (Status s = program("scene_shadow.vert", "shadow.frag", shadowProgram); !s.ok()) return s;
    if (Status s = program("sky.vert", "sky.frag", skyProgram); !s.ok()) return s;
    if (Status s = program("sprite.vert", "sprite.frag", spriteProgram); !s.ok()) return s;
    if (Status s = program("line.vert", "line.frag", lineProgram); !s.ok()) return s;
    viewProj = glGetUniformLocation(meshProgram, "uViewProj");
    eye = glGetUniformLocation(meshProgram, "uEye");
    lightCount = glGetUniformLocation(meshProgram, "uLightCount");
    lightType = glGetUniformLocation(meshProgram, "uLightType");
    lightVector = glGetUniformLocation(meshProgram, "uLightVector");
    lightColor = glGetUniformLocation(meshProgram, "uLightColor");
    shadowLight = glGetUniformLocation(meshProgram, "uShadowLight");
    lightViewProj = glGetUniformLocation(meshProgram, "uLightViewProj");
    shadowMap = glGetUniformLocation(meshProgram, "uShadow");
    wire = glGetUniformLocation(meshProgram, "uWire");
    shadowViewProj = glGetUniformLocation(shadowProgram, "uLightViewProj");
    skyInverse = glGetUniformLocation(skyProgram, "uInverseViewProj");
    skyTop = glGetUniformLocation(skyProgram, "uTop");
    skyHorizon = glGetUniformLocation(skyProgram, "uHorizon");
    spriteViewProj = glGetUniformLocation(spriteProgram, "uViewProj");
    spriteScale = glGetUniformLocation(spriteProgram, "uPixelsPerUnit");
    lineViewProj = glGetUniformLocation(lineProgram, "uViewProj");
    MakeShadowTarget(shadowFbo, shadowDepth);
    MakeShadowTarget(spareFbo, spareDepth);
    glGenVertexArrays(1, &emptyVao);
    glGenVertexArrays(1, &spriteVao);
    glGenBuffers(4, spriteBuffers);
    glGenVertexArrays(1, &lineVao);
    glGenBuffers(2, lineBuffers);
    return {};
  }

  // A depth texture compared on lookup and a framebuffer drawing into it.
  static void MakeShadowTarget(GLuint& fbo, GLuint& depth) {
    glGenTextures(1, &depth);
    glBindTexture(GL_TEXTURE_2D, depth);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  // (Re)allocates the shadow map at `size` texels a side.
  void SizeShadowMap(int size) {
    if (size == shadowSize) return;
    for (GLuint t : {shadowDepth, spareDepth}) {
      glBindTexture(GL_TEXTURE_2D, t);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT,
                   GL_FLOAT, nullptr);
    }
    shadowSize = size;
    shadowValid = false;
    spareBands = -1;
  }

  // What a list's shadow map shows: the first sun (-1: none), its view of
  // the casters' box (or the list's shadowBounds), and a key over the
  // light's view, the casting meshes and their instances.
  struct ShadowPlan {
    int light = -1;
    Eigen::Matrix4f viewProj = Eigen::Matrix4f::Identity();
    uint64_t key = 0;
  };
  ShadowPlan PlanShadow(const draw::DrawList& list) const {
    ShadowPlan plan;
    // The shadow map covers what casts shadows (a wide terrain that does not
    // cast would only spread its texels thin).
    Vec3 lo, hi;
    draw::DrawList casters;
    for (const draw::MeshDraw& d : list.meshes)
      if (d.castsShadow) casters.meshes.push_back(d);
    bool any = casters.Bounds(lo, hi);
    if (list.shadowBounds) {
      lo = list.shadowBounds->first;
      hi = list.shadowBounds->second;
      any = true;
    }
    for (size_t i = 0; i < list.lights.size() && plan.light < 0; ++i)
      if (list.lights[i].type == draw::Light::Type::kSun) plan.light = int(i);
    if (plan.light < 0 || !any) {
      plan.light = -1;
      return plan;
    }
    const Vec3 toLight = -list.lights[size_t(plan.light)].direction.cast<double>().normalized();
    plan.viewProj = SunViewProj(toLight, lo, hi);
    plan.key = Fnv(kFnvBasis, plan.viewProj.data(), sizeof(float) * 16);
    for (size_t i = 0; i < list.meshes.size(); ++i) {
      const draw::MeshDraw& d = list.meshes[i];
      if (!d.castsShadow || d.instances.empty()) continue;
      const uintptr_t key[2] = {uintptr_t(d.mesh.get()), uintptr_t(d.mesh->indices.size())};
      plan.key = Fnv(plan.key, key, sizeof key);
      for (const draw::Instance& inst : d.instances)
        plan.key = Fnv(plan.key, inst.transform.data(), sizeof(float) * 16);
    }
    return plan;
  }

  // Draws rows [size * band / bands, size * (band + 1) / bands) of the
  // shadow map in `fbo` (band 0 clears it first); the meshes' instances
  // must be uploaded.
  void DrawShadow(const draw::DrawList& list, const std::vector<GpuMesh*>& gpu,
                  const ShadowPlan& plan, GLuint fbo, int band, int bands) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, shadowSize, shadowSize);
    if (band == 0) glClear(GL_DEPTH_BUFFER_BIT);
    const int y0 = shadowSize * band / bands, y1 = shadowSize * (band + 1) / bands;
    if (bands > 1) {
      glEnable(GL_SCISSOR_TEST);
      glScissor(0, y0, shadowSize, y1 - y0);
    }
    glEnable(GL_DEPTH_TEST);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2.0f, 4.0f);
    glUseProgram(shadowProgram);
    glUniformMatrix4fv(shadowViewProj, 1, GL_FALSE, plan.viewProj.data());
    glVertexAttrib1f(kCoverageLocation, 1.0f);  // meshes without coverage
    // Coverage lines cast a screen-door shadow (shadow.frag).
    for (size_t i = 0; i < list.meshes.size(); ++i) {
      if (!list.meshes[i].castsShadow || list.meshes[i].instances.empty()) continue;
      glBindVertexArray(gpu[i]->vao);
      glDrawElementsInstanced(GL_TRIANGLES, gpu[i]->indexCount, GL_UNSIGNED_INT, nullptr,
                              GLsizei(list.meshes[i].instances.size()));
    }
    glDisable(GL_POLYGON_OFFSET_FILL);
    glDisable(GL_SCISSOR_TEST);
  }

  // The GPU copy of d's mesh, uploaded whole if it is not (yet).
  GpuMesh& Upload(const draw::MeshDraw& d) {
    GpuMesh& g = Begin(d);
    Continue(g, SIZE_MAX);
    return g;
  }

  // The GPU copy of d's mesh: its buffers allocated at their sizes and its
  // upload staged (nothing sent yet) when it is new or its palette changed.
  GpuMesh& Begin(const draw::MeshDraw& d) {
    GpuMesh& g = meshes[d.mesh.get()];
    g.used = true;
    if (g.vao && g.palette == d.palette) return g;
    if (g.vao) DeleteMesh(g);
    g = GpuMesh{};
    g.used = true;
    g.mesh = d.mesh;
    g.palette = d.palette;
    const mesh::TriangleMesh& m = *d.mesh;
    auto st = std::make_unique<Staging>();
    st->colors = VertexColors(m, d.palette);
    const size_t opaque = OpaqueFirst(m, st->sorted);
    const bool partial = !st->sorted.empty();
    glGenVertexArrays(1, &g.vao);
    glGenBuffers(3, g.buffers);
    glGenBuffers(1, &g.index);
    glGenBuffers(1, &g.instances);
    glGenBuffers(1, &g.coverage);
    glBindVertexArray(g.vao);
    const size_t nv = m.vertexCount();
    for (int k = 0; k < 3; ++k) {
      glBindBuffer(GL_ARRAY_BUFFER, g.buffers[k]);
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(nv * 12), nullptr, GL_STATIC_DRAW);
      glEnableVertexAttribArray(GLuint(k));
      glVertexAttribPointer(GLuint(k), 3, GL_FLOAT, GL_FALSE, 12, nullptr);
    }
    glBindBuffer(GL_ARRAY_BUFFER, g.instances);
    for (int c = 0; c < 4; ++c) {
      glEnableVertexAttribArray(GLuint(3 + c));
      glVertexAttribPointer(GLuint(3 + c), 4, GL_FLOAT, GL_FALSE, sizeof(GpuInstance),
                            reinterpret_cast<const void*>(size_t(16 * c)));
      glVertexAttribDivisor(GLuint(3 + c), 1);
    }
    glEnableVertexAttribArray(7);
    glVertexAttribPointer(7, 3, GL_FLOAT, GL_FALSE, sizeof(GpuInstance),
                          reinterpret_cast<const void*>(size_t(64)));
    glVertexAttribDivisor(7, 1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.index);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.indices.size() * 4), nullptr,
                 GL_STATIC_DRAW);
    if (partial) {
      glBindBuffer(GL_ARRAY_BUFFER, g.coverage);
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(nv * 4), nullptr, GL_STATIC_DRAW);
      glEnableVertexAttribArray(kCoverageLocation);
      glVertexAttribPointer(kCoverageLocation, 1, GL_FLOAT, GL_FALSE, 4, nullptr);
    } else {
      glDisableVertexAttribArray(kCoverageLocation);
    }
    glBindVertexArray(0);
    g.opaqueCount = GLsizei(partial ? opaque : m.indices.size());
    g.indexCount = GLsizei(m.indices.size());
    st->parts = {{g.buffers[0], m.positions.data(), nv * 12},
                 {g.buffers[1], m.normals.data(), nv * 12},
                 {g.buffers[2], st->colors.data(), nv * 12},
                 {g.index, partial ? st->sorted.data() : m.indices.data(), m.indices.size() * 4}};
    if (partial) st->parts.push_back({g.coverage, m.coverage.data(), nv * 4});
    g.staging = std::move(st);
    return g;
  }

  // Sends at most `budget` bytes of g's staged upload; returns the bytes
  // sent. The staging is freed once everything is on the GPU.
  size_t Continue(GpuMesh& g, size_t budget) {
    if (!g.staging) return 0;
    Staging& st = *g.staging;
    size_t sent = 0;
    while (st.part < st.parts.size() && sent < budget) {
      const Staging::Part& part = st.parts[st.part];
      const size_t n = std::min(part.bytes - st.offset, budget - sent);
      if (n > 0) {
        glNamedBufferSubData(part.buffer, GLintptr(st.offset), GLsizeiptr(n),
                             static_cast<const char*>(part.data) + st.offset);
      }
      sent += n;
      st.offset += n;
      if (st.offset == part.bytes) {
        ++st.part;
        st.offset = 0;
      }
    }
    if (st.part == st.parts.size()) g.staging.reset();
    return sent;
  }

  void UploadInstances(GpuMesh& g, const std::vector<draw::Instance>& instances) {
    std::vector<GpuInstance> data(instances.size());
    for (size_t i = 0; i < instances.size(); ++i) {
      std::copy(instances[i].transform.data(), instances[i].transform.data() + 16, data[i].model);
      for (int c = 0; c < 3; ++c) data[i].tint[c] = instances[i].tint[c];
    }
    glBindBuffer(GL_ARRAY_BUFFER, g.instances);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(GpuInstance)), data.data(),
                 GL_STREAM_DRAW);
  }

  // Fits the sun's orthographic view to the list's bounding sphere.
  Eigen::Matrix4f SunViewProj(const Vec3& toLight, const Vec3& lo, const Vec3& hi) const {
    Camera light;
    light.orthographic = true;
    light.target = (lo + hi) / 2;
    const double r = SunShadowRadius(lo, hi);
    light.distance = 3 * r;
    light.elevation = std::asin(std::clamp(toLight.y(), -1.0, 1.0)) * kRadToDeg;
    light.azimuth = std::atan2(toLight.x(), toLight.z()) * kRadToDeg;
    light.orthoHeight = 2 * r;
    return light.ViewProjection(1.0).cast<float>();
  }
};

double SunShadowRadius(const Vec3& lo, const Vec3& hi) {
  return std::max((hi - lo).norm() / 2, 1e-3) * 1.05;
}

double ShadowTexelsPerUnit(const mesh::Box& bounds) {
  return Renderer::kDefaultShadowMapSize / (2 * SunShadowRadius(bounds.lo, bounds.hi));
}

void Renderer::DestroyScenePass(ScenePass* pass) {
  delete pass;
}

Status Renderer::InitScenePass() {
  if (scene_) return {};
  auto* pass = new ScenePass();
  if (Status s = pass->Init(shaderDir_); !s.ok()) {
    delete pass;
    return s;
  }
  scene_ = pass;
  return {};
}

Expected<bool> Renderer::Stage(const draw::DrawList& list, size_t budgetBytes) {
  if (Status s = list.Check(); !s.ok()) return s.error();
  if (Status s = InitScenePass(); !s.ok()) return s.error();
  ScenePass& p = *scene_;
  p.staged.clear();
  bool complete = true;
  size_t left = budgetBytes;
  for (const draw::MeshDraw& d : list.meshes) {
    p.staged.insert(d.mesh.get());
    auto it = p.meshes.find(d.mesh.get());
    const bool fresh = it == p.meshes.end() || it->second.palette != d.palette;
    if (!fresh && !it->second.staging) continue;  // already on the GPU
    if (left == 0) {
      complete = false;
      continue;
    }
    GpuMesh& g = p.Begin(d);
    left -= p.Continue(g, left);
    complete = complete && !g.staging;
  }
  if (!complete) return false;
  // Then its shadow map, a band a call, into the spare map Draw swaps in.
  p.SizeShadowMap(shadowMapSize_);
  const ScenePass::ShadowPlan shadow = p.PlanShadow(list);
  if (shadow.light < 0 || (p.shadowValid && shadow.key == p.shadowKey)) return true;
  if (p.spareKey != shadow.key || p.spareBands < 0) {
    p.spareKey = shadow.key;
    p.spareBands = 0;
  }
  if (p.spareBands == kShadowBands) return true;
  std::vector<GpuMesh*> gpu;
  for (const draw::MeshDraw& d : list.meshes) {
    GpuMesh& g = p.Begin(d);
    p.UploadInstances(g, d.instances);
    gpu.push_back(&g);
  }
  p.DrawShadow(list, gpu, shadow, p.spareFbo, p.spareBands, kShadowBands);
  ++p.spareBands;
  return p.spareBands == kShadowBands;
}

Status Renderer::Draw(const draw::DrawList& list, const Camera& camera) {
  if (Status s = list.Check(); !s.ok()) return s;
  if (Status s = InitScenePass(); !s.ok()) return s;
  ScenePass& p = *scene_;
  p.SizeShadowMap(shadowMapSize_);
  for (auto& [k, m] : p.meshes) m.used = false;
  std::vector<GpuMesh*> gpu;
  for (const draw::MeshDraw& d : list.meshes) {
    GpuMesh& g = p.Upload(d);
    p.UploadInstances(g, d.instances);
    gpu.push_back(&g);
  }
  // Meshes the list no longer shares (and the last Stage() list does not
  // have) are freed.
  for (auto it = p.meshes.begin(); it != p.meshes.end();) {
    if (it->second.used || p.staged.count(it->first)) {
      ++it;
    } else {
      DeleteMesh(it->second);
      it = p.meshes.erase(it);
    }
  }

  // Lights: the first sun casts the shadow. The map is drawn again only
  // when what it shows changed: the light's view, the casting meshes or
  // their instances (a still plant in the viewer costs one shadow pass,
  // not one per frame), or taken from Stage() when it drew this one.
  const ScenePass::ShadowPlan shadow = p.PlanShadow(list);
  int shadowLight = shadow.light;
  const Eigen::Matrix4f lightViewProj = shadow.viewProj;
  if (shadowLight >= 0 && p.shadowValid && shadow.key == p.shadowKey) {
    // The map drawn for an earlier frame still holds.
  } else if (shadowLight >= 0 && p.spareBands == kShadowBands && shadow.key == p.spareKey) {
    std::swap(p.shadowFbo, p.spareFbo);
    std::swap(p.shadowDepth, p.spareDepth);
    p.shadowKey = shadow.key;
    p.shadowValid = true;
    p.spareBands = -1;
  } else if (shadowLight >= 0) {
    p.shadowKey = shadow.key;
    p.shadowValid = true;
    p.DrawShadow(list, gpu, shadow, p.shadowFbo, 0, 1);
  }

  glBindFramebuffer(GL_FRAMEBUFFER, MultisampleFramebuffer());
  glViewport(0, 0, width_, height_);
  const mesh::Vec3f clear = mesh::ToSrgb(list.background);
  glClearColor(clear.x(), clear.y(), clear.z(), 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_MULTISAMPLE);
  const double aspect = double(width_) / height_;
  const Mat4 vpd = camera.ViewProjection(aspect);
  const Eigen::Matrix4f vp = vpd.cast<float>();

  if (list.sky) {
    glDisable(GL_DEPTH_TEST);
    glUseProgram(p.skyProgram);
    const Eigen::Matrix4f inv = vpd.inverse().cast<float>();
    glUniformMatrix4fv(p.skyInverse, 1, GL_FALSE, inv.data());
    glUniform3fv(p.skyTop, 1, list.sky->top.data());
    glUniform3fv(p.skyHorizon, 1, list.sky->horizon.data());
    glBindVertexArray(p.emptyVao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glEnable(GL_DEPTH_TEST);

  if (!list.meshes.empty()) {
    // No lights: a default key, fill and ambient, as the single-mesh path.
    const std::vector<draw::Light> lights =
        list.lights.empty() ? draw::DefaultLights() : list.lights;
    int types[draw::kMaxLights];
    float vectors[3 * draw::kMaxLights], colors[3 * draw::kMaxLights];
    for (size_t i = 0; i < lights.size(); ++i) {
      const draw::Light& l = lights[i];
      types[i] = l.type == draw::Light::Type::kSun       ? 0
                 : l.type == draw::Light::Type::kAmbient ? 1
                                                         : 2;
      const mesh::Vec3f v =
          l.type == draw::Light::Type::kPoint ? l.position : mesh::Vec3f(-l.direction.normalized());
      const mesh::Vec3f c = l.color * l.intensity;
      for (int k = 0; k < 3; ++k) {
        vectors[3 * i + size_t(k)] = v[k];
        colors[3 * i + size_t(k)] = c[k];
      }
    }
    glUseProgram(p.meshProgram);
    glUniformMatrix4fv(p.viewProj, 1, GL_FALSE, vp.data());
    const Eigen::Vector3f eye = camera.Eye().cast<float>();
    glUniform3fv(p.eye, 1, eye.data());
    glUniform1i(p.lightCount, GLint(lights.size()));
    glUniform1iv(p.lightType, GLsizei(lights.size()), types);
    glUniform3fv(p.lightVector, GLsizei(lights.size()), vectors);
    glUniform3fv(p.lightColor, GLsizei(lights.size()), colors);
    glUniform1i(p.shadowLight, shadowLight);
    glUniformMatrix4fv(p.lightViewProj, 1, GL_FALSE, lightViewProj.data());
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, p.shadowDepth);
    glUniform1i(p.shadowMap, 0);
    glVertexAttrib1f(kCoverageLocation, 1.0f);  // meshes without coverage
    glUniform1i(p.wire, 0);
    for (size_t i = 0; i < list.meshes.size(); ++i) {
      if (list.meshes[i].instances.empty()) continue;
      glBindVertexArray(gpu[i]->vao);
      glDrawElementsInstanced(GL_TRIANGLES, gpu[i]->opaqueCount, GL_UNSIGNED_INT, nullptr,
                              GLsizei(list.meshes[i].instances.size()));
    }
    // Partial coverage (coverage lines and points) blended over everything
    // opaque, depth tested but not written, as in the single-mesh path.
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    for (size_t i = 0; i < list.meshes.size(); ++i) {
      const std::pair<GLsizei, GLsizei> range{gpu[i]->opaqueCount, gpu[i]->indexCount};
      if (list.meshes[i].instances.empty() || range.first == range.second) continue;
      glBindVertexArray(gpu[i]->vao);
      glDrawElementsInstanced(GL_TRIANGLES, range.second - range.first, GL_UNSIGNED_INT,
                              reinterpret_cast<const void*>(size_t(range.first) * 4),
                              GLsizei(list.meshes[i].instances.size()));
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    if (list.wireframe) {
      // The triangles' edges over the shaded meshes, pulled toward the eye.
      glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      glEnable(GL_POLYGON_OFFSET_LINE);
      glPolygonOffset(-1.0f, -1.0f);
      glUniform1i(p.wire, 1);
      for (size_t i = 0; i < list.meshes.size(); ++i) {
        if (list.meshes[i].instances.empty() || !list.meshes[i].castsShadow) continue;
        glBindVertexArray(gpu[i]->vao);
        glDrawElementsInstanced(GL_TRIANGLES, gpu[i]->indexCount, GL_UNSIGNED_INT, nullptr,
                                GLsizei(list.meshes[i].instances.size()));
      }
      glUniform1i(p.wire, 0);
      glDisable(GL_POLYGON_OFFSET_LINE);
      glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
  }

  for (const draw::Lines& l : list.lines) {
    if (l.points.empty()) continue;
    glUseProgram(p.lineProgram);
    glUniformMatrix4fv(p.lineViewProj, 1, GL_FALSE, vp.data());
    glBindVertexArray(p.lineVao);
    const void* data[2] = {l.points.data(), l.colors.data()};
    for (int k = 0; k < 2; ++k) {
      glBindBuffer(GL_ARRAY_BUFFER, p.lineBuffers[k]);
      glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(l.points.size() * 12), data[k], GL_STREAM_DRAW);
      glEnableVertexAttribArray(GLuint(k));
      glVertexAttribPointer(GLuint(k), 3, GL_FLOAT, GL_FALSE, 12, nullptr);
    }
    glDrawArrays(GL_LINES, 0, GLsizei(l.points.size()));
  }

  // Sprites last: blended, depth-tested, not writing depth.
  if (!list.sprites.empty()) {
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(GL_BLEND);
    glDepthMask(GL_FALSE);
    glUseProgram(p.spriteProgram);
    glUniformMatrix4fv(p.spriteViewProj, 1, GL_FALSE, vp.data());
    glUniform1f(p.spriteScale, float(camera.Projection(aspect)(1, 1) * height_ * 0.5));
    glBindVertexArray(p.spriteVao);
    for (const draw::Sprites& s : list.sprites) {
      if (s.positions.empty()) continue;
      const size_t n = s.positions.size();
      const std::vector<float> opaque(s.alphas.empty() ? n : 0, 1.0f);
      const std::vector<float>& alphas = s.alphas.empty() ? opaque : s.alphas;
      const void* data[4] = {s.positions.data(), s.sizes.data(), s.colors.data(), alphas.data()};
      const int widths[4] = {3, 1, 3, 1};
      for (int k = 0; k < 4; ++k) {
        glBindBuffer(GL_ARRAY_BUFFER, p.spriteBuffers[k]);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 4 * size_t(widths[k])), data[k],
                     GL_STREAM_DRAW);
        glEnableVertexAttribArray(GLuint(k));
        glVertexAttribPointer(GLuint(k), widths[k], GL_FLOAT, GL_FALSE, 4 * widths[k], nullptr);
      }
      if (s.blend == draw::Blend::kAdditive)
        glBlendFunc(GL_SRC_ALPHA, GL_ONE);
      else
        glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      glDrawArrays(GL_POINTS, 0, GLsizei(n));
    }
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
  }
  glBindVertexArray(0);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, MultisampleFramebuffer());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, ResolveFramebuffer());
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  return {};
}

}  // namespace sylva::render
