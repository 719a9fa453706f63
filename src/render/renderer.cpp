#include "render/renderer.h"

#include <GL/glew.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "core/atomic_file.h"
#include "render/gl_program.h"

namespace sylva::render {

namespace fs = std::filesystem;

std::string FindShaderDir() {
  if (const char* env = std::getenv("SYLVA_SHADER_DIR")) return env;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (fs::path dir = exe.parent_path(); !dir.empty(); dir = dir.parent_path()) {
      if (fs::is_regular_file(dir / "shaders" / "mesh.vert", ec)) return (dir / "shaders").string();
      if (fs::is_regular_file(dir / "share" / "sylva" / "shaders" / "mesh.vert", ec))
        return (dir / "share" / "sylva" / "shaders").string();
      if (dir == dir.root_path()) break;
    }
  }
  return (fs::path(SYLVA_DATA_DIR) / "shaders").string();
}

// Texels on a side of the key light's shadow map.
constexpr int kShadowMapSize = 2048;

struct Renderer::Gl {
  GLuint meshProgram = 0, lineProgram = 0, shadowProgram = 0;
  GLint meshViewProj = -1, meshEye = -1, lineViewProj = -1;
  GLint meshKeyDir = -1, meshLightViewProj = -1, meshShadow = -1, meshShadows = -1;
  GLint meshWire = -1;
  GLint shadowLightViewProj = -1;
  GLuint shadowFbo = 0, shadowDepth = 0;
  static constexpr int kShadowSize = kShadowMapSize;
  Eigen::Matrix4f lightViewProj = Eigen::Matrix4f::Identity();
  bool haveShadow = false;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // mesh bounds
  GLuint meshVao = 0, meshBuffers[3] = {0, 0, 0}, meshIndex = 0, meshCoverage = 0;
  GLsizei meshIndexCount = 0;
  // Indices [0, opaqueIndexCount) are opaque; the rest have coverage < 1
  // somewhere and are blended after everything opaque, without depth writes.
  GLsizei opaqueIndexCount = 0;
  GLuint lineVao = 0, lineBuffers[2] = {0, 0};
  GLsizei lineVertexCount = 0;
  GLuint pointProgram = 0, pointVao = 0, pointBuffers[3] = {0, 0, 0};
  GLint pointViewProj = -1, pointScale = -1, pointOrtho = -1;
  GLsizei pointCount = 0;
  GLuint msFbo = 0, msColor = 0, msDepth = 0, resolveFbo = 0, resolveColor = 0;
};

static Diagnostic ShaderError(const std::string& file, const std::string& message) {
  Diagnostic d;
  d.loc.file = file;
  d.message = message;
  return d;
}

std::vector<mesh::Vec3f> VertexColors(const mesh::TriangleMesh& m, const mesh::Palette& palette) {
  std::vector<mesh::Vec3f> color(m.vertexCount(), mesh::Srgb(0.8f, 0.8f, 0.8f));
  if (palette.empty()) return color;
  std::vector<uint8_t> seen(m.vertexCount(), 0);
  for (size_t t = 0; t < m.triangleCount(); ++t)
    for (int e = 0; e < 3; ++e) {
      const uint32_t i = m.indices[3 * t + size_t(e)];
      if (!seen[i]) {
        seen[i] = 1;
        color[i] = palette[m.material[t] % palette.size()];
      }
    }
  return color;
}

void UploadVertexAttributes(const unsigned buffers[3], const mesh::TriangleMesh& m,
                            const std::vector<mesh::Vec3f>& colors) {
  const void* data[3] = {m.positions.data(), m.normals.data(), colors.data()};
  for (int k = 0; k < 3; ++k) {
    glBindBuffer(GL_ARRAY_BUFFER, buffers[k]);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertexCount() * 12), data[k], GL_STATIC_DRAW);
    glEnableVertexAttribArray(GLuint(k));
    glVertexAttribPointer(GLuint(k), 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  }
}

size_t OpaqueFirst(const mesh::TriangleMesh& m, std::vector<uint32_t>& sorted) {
  sorted.clear();
  const bool partial =
      m.coverage.size() == m.vertexCount() &&
      std::any_of(m.coverage.begin(), m.coverage.end(), [](float c) { return c < 1; });
  if (!partial) return m.indices.size();
  sorted.reserve(m.indices.size());
  auto translucent = [&](size_t t) {
    return m.coverage[m.indices[3 * t]] < 1 || m.coverage[m.indices[3 * t + 1]] < 1 ||
           m.coverage[m.indices[3 * t + 2]] < 1;
  };
  size_t opaque = 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t t = 0; t < m.triangleCount(); ++t) {
      if (translucent(t) != (pass == 1)) continue;
      sorted.insert(sorted.end(), &m.indices[3 * t], &m.indices[3 * t] + 3);
    }
    if (pass == 0) opaque = sorted.size();
  }
  return opaque;
}

size_t UploadIndicesOpaqueFirst(const mesh::TriangleMesh& m, unsigned coverageBuffer,
                                unsigned location) {
  std::vector<uint32_t> sorted;
  const size_t opaque = OpaqueFirst(m, sorted);
  if (sorted.empty()) {
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(m.indices.size() * 4), m.indices.data(),
                 GL_STATIC_DRAW);
    glDisableVertexAttribArray(location);
    return opaque;
  }
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(sorted.size() * 4), sorted.data(),
               GL_STATIC_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, coverageBuffer);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.coverage.size() * 4), m.coverage.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, 1, GL_FLOAT, GL_FALSE, 4, nullptr);
  return opaque;
}

Expected<unsigned> CompileProgram(const std::string& dir, const std::string& name) {
  return CompileProgram(dir, name + ".vert", name + ".frag");
}

Expected<unsigned> CompileProgram(const std::string& dir, const std::string& vert,
                                  const std::string& frag) {
  const std::string name = vert.substr(0, vert.rfind('.'));
  GLuint shaders[2];
  const std::string files[2] = {vert, frag};
  const GLenum kinds[2] = {GL_VERTEX_SHADER, GL_FRAGMENT_SHADER};
  for (int k = 0; k < 2; ++k) {
    const std::string path = (fs::path(dir) / files[k]).string();
    auto text = ReadFile(path);
    if (!text) return ShaderError(path, "cannot read shader: " + text.error().message);
    shaders[k] = glCreateShader(kinds[k]);
    const char* src = text->c_str();
    glShaderSource(shaders[k], 1, &src, nullptr);
    glCompileShader(shaders[k]);
    GLint ok = 0;
    glGetShaderiv(shaders[k], GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[4096];
      glGetShaderInfoLog(shaders[k], sizeof log, nullptr, log);
      for (int j = 0; j <= k; ++j) glDeleteShader(shaders[j]);
      return ShaderError(path, std::string("GLSL compilation failed: ") + log);
    }
  }
  GLuint program = glCreateProgram();
  glAttachShader(program, shaders[0]);
  glAttachShader(program, shaders[1]);
  glLinkProgram(program);
  glDeleteShader(shaders[0]);
  glDeleteShader(shaders[1]);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096];
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    glDeleteProgram(program);
    return ShaderError((fs::path(dir) / name).string() + ".{vert,frag}",
                       std::string("GLSL link failed: ") + log);
  }
  return program;
}

Expected<std::unique_ptr<Renderer>> Renderer::Create(const std::string& shaderDir) {
  std::unique_ptr<Renderer> r(new Renderer());
  r->gl_ = std::make_unique<Gl>();
  r->shaderDir_ = shaderDir;
  Gl& g = *r->gl_;
  auto mesh = CompileProgram(shaderDir, "mesh");
  if (!mesh) return mesh.error();
  g.meshProgram = *mesh;
  auto line = CompileProgram(shaderDir, "line");
  if (!line) return line.error();
  g.lineProgram = *line;
  g.meshViewProj = glGetUniformLocation(g.meshProgram, "uViewProj");
  g.meshEye = glGetUniformLocation(g.meshProgram, "uEye");
  g.meshKeyDir = glGetUniformLocation(g.meshProgram, "uKeyDir");
  g.meshLightViewProj = glGetUniformLocation(g.meshProgram, "uLightViewProj");
  g.meshShadow = glGetUniformLocation(g.meshProgram, "uShadow");
  g.meshShadows = glGetUniformLocation(g.meshProgram, "uShadows");
  g.meshWire = glGetUniformLocation(g.meshProgram, "uWire");
  auto shadow = CompileProgram(shaderDir, "shadow");
  if (!shadow) return shadow.error();
  g.shadowProgram = *shadow;
  g.shadowLightViewProj = glGetUniformLocation(g.shadowProgram, "uLightViewProj");
  glGenTextures(1, &g.shadowDepth);
  glBindTexture(GL_TEXTURE_2D, g.shadowDepth);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, Gl::kShadowSize, Gl::kShadowSize, 0,
               GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glGenFramebuffers(1, &g.shadowFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, g.shadowFbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g.shadowDepth, 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  g.lineViewProj = glGetUniformLocation(g.lineProgram, "uViewProj");
  auto point = CompileProgram(shaderDir, "point");
  if (!point) return point.error();
  g.pointProgram = *point;
  g.pointViewProj = glGetUniformLocation(g.pointProgram, "uViewProj");
  g.pointScale = glGetUniformLocation(g.pointProgram, "uPixelsPerUnit");
  g.pointOrtho = glGetUniformLocation(g.pointProgram, "uOrthographic");
  glGenVertexArrays(1, &g.pointVao);
  glGenBuffers(3, g.pointBuffers);
  glGenVertexArrays(1, &g.meshVao);
  glGenBuffers(3, g.meshBuffers);
  glGenBuffers(1, &g.meshIndex);
  glGenBuffers(1, &g.meshCoverage);
  glGenVertexArrays(1, &g.lineVao);
  glGenBuffers(2, g.lineBuffers);
  return r;
}

Renderer::~Renderer() {
  DestroyScenePass(scene_);
  if (!gl_) return;
  Gl& g = *gl_;
  glDeleteProgram(g.meshProgram);
  glDeleteProgram(g.shadowProgram);
  glDeleteFramebuffers(1, &g.shadowFbo);
  glDeleteTextures(1, &g.shadowDepth);
  glDeleteProgram(g.lineProgram);
  glDeleteBuffers(3, g.meshBuffers);
  glDeleteBuffers(1, &g.meshIndex);
  glDeleteBuffers(1, &g.meshCoverage);
  glDeleteBuffers(2, g.lineBuffers);
  glDeleteVertexArrays(1, &g.meshVao);
  glDeleteVertexArrays(1, &g.lineVao);
  glDeleteProgram(g.pointProgram);
  glDeleteBuffers(3, g.pointBuffers);
  glDeleteVertexArrays(1, &g.pointVao);
  glDeleteFramebuffers(1, &g.msFbo);
  glDeleteFramebuffers(1, &g.resolveFbo);
  glDeleteRenderbuffers(1, &g.msColor);
  glDeleteRenderbuffers(1, &g.msDepth);
  glDeleteRenderbuffers(1, &g.resolveColor);
}

Status Renderer::Resize(int width, int height, int samples) {
  if (width < 1 || height < 1 || width > 8192 || height > 8192) {
    Diagnostic d;
    d.message = "image size " + std::to_string(width) + "x" + std::to_string(height) +
                " is outside 1x1 .. 8192x8192";
    return d;
  }
  Gl& g = *gl_;
  width_ = width;
  height_ = height;
  glDeleteFramebuffers(1, &g.msFbo);
  glDeleteFramebuffers(1, &g.resolveFbo);
  glDeleteRenderbuffers(1, &g.msColor);
  glDeleteRenderbuffers(1, &g.msDepth);
  glDeleteRenderbuffers(1, &g.resolveColor);
  GLint maxSamples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  samples = std::max(1, std::min(samples, int(maxSamples)));
  glGenRenderbuffers(1, &g.msColor);
  glBindRenderbuffer(GL_RENDERBUFFER, g.msColor);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &g.msDepth);
  glBindRenderbuffer(GL_RENDERBUFFER, g.msDepth);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
  glGenFramebuffers(1, &g.msFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, g.msFbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.msColor);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g.msDepth);
  const GLenum ms = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  glGenRenderbuffers(1, &g.resolveColor);
  glBindRenderbuffer(GL_RENDERBUFFER, g.resolveColor);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glGenFramebuffers(1, &g.resolveFbo);
  glBindFramebuffer(GL_FRAMEBUFFER, g.resolveFbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.resolveColor);
  const GLenum rs = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (ms != GL_FRAMEBUFFER_COMPLETE || rs != GL_FRAMEBUFFER_COMPLETE) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.message = "the OpenGL framebuffer is incomplete";
    return d;
  }
  return {};
}

void Renderer::SetMesh(const mesh::TriangleMesh& m, const mesh::Palette& palette,
                       const mesh::Box* bounds) {
  Gl& g = *gl_;
  const std::vector<mesh::Vec3f> color = VertexColors(m, palette);
  glBindVertexArray(g.meshVao);
  UploadVertexAttributes(g.meshBuffers, m, color);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.meshIndex);
  g.meshIndexCount = GLsizei(m.indices.size());
  g.opaqueIndexCount = GLsizei(UploadIndicesOpaqueFirst(m, g.meshCoverage, 3));
  glBindVertexArray(0);
  g.lo = g.hi = Vec3::Zero();
  if (m.vertexCount()) {
    g.lo = g.hi = m.positions[0].cast<double>();
    for (const auto& p : m.positions) {
      g.lo = g.lo.cwiseMin(p.cast<double>());
      g.hi = g.hi.cwiseMax(p.cast<double>());
    }
  }
  if (bounds && (bounds->lo.array() <= bounds->hi.array()).all()) {
    g.lo = bounds->lo;
    g.hi = bounds->hi;
  }
  RenderShadowMap();
}

// The key light is fixed in world space; its orthographic view covers the
// mesh's bounding sphere, so the map is made once per mesh.
// The same key as draw::DefaultLights (the scene pass's default rig).
static const Vec3 kKeyDir = -draw::DefaultLights()[0].direction.cast<double>().normalized();

Vec3 KeyLightDirection() {
  return kKeyDir;
}

// The radius of the sphere the light's orthographic view covers.
static double ShadowRadius(const Vec3& lo, const Vec3& hi) {
  return std::max((hi - lo).norm() / 2, 1e-3) * 1.2;
}

void Renderer::RenderShadowMap() {
  Gl& g = *gl_;
  g.haveShadow = false;
  if (!g.meshIndexCount) return;
  Camera light;
  light.orthographic = true;
  light.target = (g.lo + g.hi) / 2;
  const double r = ShadowRadius(g.lo, g.hi);
  light.distance = 3 * r;
  light.elevation = std::asin(kKeyDir.y()) * kRadToDeg;
  light.azimuth = std::atan2(kKeyDir.x(), kKeyDir.z()) * kRadToDeg;
  light.orthoHeight = 2 * r;
  g.lightViewProj = light.ViewProjection(1.0).cast<float>();
  glBindFramebuffer(GL_FRAMEBUFFER, g.shadowFbo);
  glViewport(0, 0, Gl::kShadowSize, Gl::kShadowSize);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(2.0f, 4.0f);
  glUseProgram(g.shadowProgram);
  glUniformMatrix4fv(g.shadowLightViewProj, 1, GL_FALSE, g.lightViewProj.data());
  glBindVertexArray(g.meshVao);
  // Coverage lines and points, drawn wider than they are, cast a
  // screen-door shadow (shadow.frag) of their mean darkness.
  glVertexAttrib1f(3, 1.0f);  // coverage of a mesh without any
  glDrawElements(GL_TRIANGLES, g.meshIndexCount, GL_UNSIGNED_INT, nullptr);
  glBindVertexArray(0);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  g.haveShadow = true;
}

Status Renderer::SetLines(const LineBatch& lines) {
  if (lines.colors.size() != lines.points.size()) {
    Diagnostic d;
    d.message = "LineBatch has " + std::to_string(lines.points.size()) + " points but " +
                std::to_string(lines.colors.size()) + " colors (one a point)";
    return d;
  }
  Gl& g = *gl_;
  glBindVertexArray(g.lineVao);
  const void* data[2] = {lines.points.data(), lines.colors.data()};
  for (int k = 0; k < 2; ++k) {
    glBindBuffer(GL_ARRAY_BUFFER, g.lineBuffers[k]);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(lines.points.size() * 12), data[k], GL_STATIC_DRAW);
    glEnableVertexAttribArray(GLuint(k));
    glVertexAttribPointer(GLuint(k), 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  }
  g.lineVertexCount = GLsizei(lines.points.size());
  glBindVertexArray(0);
  return {};
}

Status Renderer::SetPoints(const PointBatch& points) {
  if (points.sizes.size() != points.positions.size() ||
      points.colors.size() != points.positions.size()) {
    Diagnostic d;
    d.message = "PointBatch has " + std::to_string(points.positions.size()) + " positions but " +
                std::to_string(points.sizes.size()) + " sizes and " +
                std::to_string(points.colors.size()) + " colors (one of each a point)";
    return d;
  }
  Gl& g = *gl_;
  glBindVertexArray(g.pointVao);
  const size_t n = points.positions.size();
  glBindBuffer(GL_ARRAY_BUFFER, g.pointBuffers[0]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 12), points.positions.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, g.pointBuffers[1]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 4), points.sizes.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, 4, nullptr);
  glBindBuffer(GL_ARRAY_BUFFER, g.pointBuffers[2]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(n * 12), points.colors.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 12, nullptr);
  g.pointCount = GLsizei(n);
  glBindVertexArray(0);
  return {};
}

void Renderer::Draw(const Camera& camera) {
  Gl& g = *gl_;
  glBindFramebuffer(GL_FRAMEBUFFER, g.msFbo);
  glViewport(0, 0, width_, height_);
  const mesh::Vec3f clear = mesh::ToSrgb(background_);  // the framebuffer holds sRGB
  glClearColor(clear.x(), clear.y(), clear.z(), 1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glEnable(GL_MULTISAMPLE);
  const Eigen::Matrix4f vp = camera.ViewProjection(double(width_) / height_).cast<float>();
  if (g.meshIndexCount) {
    glUseProgram(g.meshProgram);
    glUniformMatrix4fv(g.meshViewProj, 1, GL_FALSE, vp.data());
    const Eigen::Vector3f eye = camera.Eye().cast<float>();
    glUniform3fv(g.meshEye, 1, eye.data());
    const Eigen::Vector3f key = kKeyDir.cast<float>();
    glUniform3fv(g.meshKeyDir, 1, key.data());
    glUniformMatrix4fv(g.meshLightViewProj, 1, GL_FALSE, g.lightViewProj.data());
    glUniform1i(g.meshShadows, shadows_ && g.haveShadow ? 1 : 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g.shadowDepth);
    glUniform1i(g.meshShadow, 0);
    glBindVertexArray(g.meshVao);
    glUniform1i(g.meshWire, 0);
    glVertexAttrib1f(3, 1.0f);  // coverage of a mesh without any
    glDrawElements(GL_TRIANGLES, g.opaqueIndexCount, GL_UNSIGNED_INT, nullptr);
    if (wireframe_) {
      // The triangles' edges over the shaded mesh, pulled toward the eye.
      glPolygonMode(GL_FRONT_AND_BACK, GL_LINE);
      glEnable(GL_POLYGON_OFFSET_LINE);
      glPolygonOffset(-1.0f, -1.0f);
      glUniform1i(g.meshWire, 1);
      glDrawElements(GL_TRIANGLES, g.meshIndexCount, GL_UNSIGNED_INT, nullptr);
      glUniform1i(g.meshWire, 0);
      glDisable(GL_POLYGON_OFFSET_LINE);
      glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
    }
    if (g.opaqueIndexCount < g.meshIndexCount) {
      // Coverage in alpha, blended over everything opaque in the encoded
      // (sRGB) values the target holds, as the multisample resolve averages
      // them; depth tested but not written, so overlapping twigs add up.
      glBindVertexArray(g.meshVao);
      glEnable(GL_BLEND);
      glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
      glDepthMask(GL_FALSE);
      glDrawElements(GL_TRIANGLES, g.meshIndexCount - g.opaqueIndexCount, GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(size_t(g.opaqueIndexCount) * 4));
      glDepthMask(GL_TRUE);
      glDisable(GL_BLEND);
    }
  }
  if (g.pointCount) {
    glEnable(GL_PROGRAM_POINT_SIZE);
    glUseProgram(g.pointProgram);
    glUniformMatrix4fv(g.pointViewProj, 1, GL_FALSE, vp.data());
    // Projection scale: a diameter d at clip w covers d * P11 * height / 2 / w pixels.
    const Mat4 proj = camera.Projection(double(width_) / height_);
    glUniform1f(g.pointScale, float(proj(1, 1) * height_ * 0.5));
    glUniform1i(g.pointOrtho, camera.orthographic ? 1 : 0);
    glBindVertexArray(g.pointVao);
    glDrawArrays(GL_POINTS, 0, g.pointCount);
  }
  if (g.lineVertexCount) {
    glUseProgram(g.lineProgram);
    glUniformMatrix4fv(g.lineViewProj, 1, GL_FALSE, vp.data());
    glBindVertexArray(g.lineVao);
    glDrawArrays(GL_LINES, 0, g.lineVertexCount);
  }
  glBindVertexArray(0);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.msFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.resolveFbo);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
}

unsigned Renderer::MultisampleFramebuffer() const {
  return gl_->msFbo;
}
unsigned Renderer::ResolveFramebuffer() const {
  return gl_->resolveFbo;
}

void Renderer::Finish() {
  glFinish();
}

void Renderer::PresentToWindow(int width, int height) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->resolveFbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

// Reads the bound read framebuffer; OpenGL's rows run bottom to top.
static Image ReadBound(int width, int height) {
  Image img;
  img.width = width;
  img.height = height;
  img.rgba.resize(size_t(width) * size_t(height) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, img.rgba.data());
  const size_t row = size_t(width) * 4;
  std::vector<uint8_t> tmp(row);
  for (int y = 0; y < height / 2; ++y) {
    uint8_t* a = &img.rgba[size_t(y) * row];
    uint8_t* b = &img.rgba[size_t(height - 1 - y) * row];
    std::copy(a, a + row, tmp.begin());
    std::copy(b, b + row, a);
    std::copy(tmp.begin(), tmp.end(), b);
  }
  for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;  // opaque
  return img;
}

Image Renderer::ReadPixels() {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, gl_->resolveFbo);
  return ReadBound(width_, height_);
}

Image ReadWindowPixels(int width, int height) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  glReadBuffer(GL_BACK);
  return ReadBound(width, height);
}

namespace {

std::string LowerExtension(const std::string& path) {
  const size_t slash = path.rfind('/');
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Status EncodeAndWrite(const Image& image, const std::string& path, bool jpeg) {
  // PNG rows all with the Sub filter instead of stb's per-row trial of all
  // five: the same pixels, a 1920x1080 render written in about half the
  // time (2.6a n=20: 180-250 -> 76-113 ms) and a smaller file (511 -> 491
  // KB). Set once, before any encoding (stb reads a global).
  static const bool subFilter = (stbi_write_force_png_filter = 1, true);
  (void)subFilter;
  std::string bytes;
  auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
  };
  const int ok = jpeg ? stbi_write_jpg_to_func(append, &bytes, image.width, image.height, 4,
                                               image.rgba.data(), 95)
                      : stbi_write_png_to_func(append, &bytes, image.width, image.height, 4,
                                               image.rgba.data(), image.width * 4);
  if (!ok) {
    Diagnostic d;
    d.kind = ErrorKind::kRuntime;
    d.loc.file = path;
    d.message = jpeg ? "JPEG encoding failed" : "PNG encoding failed";
    return d;
  }
  AtomicFile f;
  Status s = f.Open(path);
  if (s.ok()) s = f.Write(bytes);
  if (s.ok()) s = f.Commit();
  return s;
}

}  // namespace

Status WritePng(const Image& image, const std::string& path) {
  return EncodeAndWrite(image, path, false);
}

bool IsImagePath(const std::string& path) {
  const std::string ext = LowerExtension(path);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

Status WriteImage(const Image& image, const std::string& path) {
  if (!IsImagePath(path)) {
    Diagnostic d;
    d.loc.file = path;
    d.message = "unknown image format; use .png, .jpg or .jpeg";
    return d;
  }
  const std::string ext = LowerExtension(path);
  return EncodeAndWrite(image, path, ext != ".png");
}

}  // namespace sylva::render
