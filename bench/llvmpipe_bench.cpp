// The reference for raster_bench's BM_RenderBody: the same scene drawn by
// Mesa's llvmpipe (Debian's software OpenGL) through OSMesa, timed side by
// side on the same machine. Same body mesh and camera (bench/harness/body_scene.h),
// Lambert with the same key light, ambient and albedo evaluated per fragment
// (a GLSL shader: normalize the interpolated vertex normal, like our smooth
// shading), depth test on, back faces culled (counter-clockwise = front), and
// every frame: positions and normals uploaded (the body is skinned per frame
// in the app), clear, draw, glReadPixels of RGBA8 into a buffer.
//
// Thread count: llvmpipe reads LP_NUM_THREADS once, when the first context
// creates its screen, so one process runs one thread count. main() sets it
// to 1 when it is unset; run once per count:
//   LP_NUM_THREADS=1 build/bench/bench/llvmpipe_bench
//   LP_NUM_THREADS=2 build/bench/bench/llvmpipe_bench
// (LP_NUM_THREADS=0 rasterizes on the calling thread; with N >= 1 the calling
// thread does vertex work and binning and N threads rasterize.) The row name
// and the "threads" counter give the count in use; the label is GL_RENDERER.
//
// per_vertex:1 rows use fixed-function GL lighting instead (one directional
// light, the same Lambert terms evaluated per vertex and interpolated:
// Gouraud, cheaper per pixel than what our renderer does).
//
// Optional (bench only): built when pkg-config finds osmesa (Debian's
// libosmesa6-dev). Args: width, height, threads (from LP_NUM_THREADS),
// per_vertex (0 GLSL per fragment, 1 fixed-function per vertex).

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

#define GL_GLEXT_PROTOTYPES 1
#include <GL/osmesa.h>
#include <GL/gl.h>
#include <GL/glext.h>

#include <benchmark/benchmark.h>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "bench/harness/body_scene.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/raster/shading.h"

namespace {

const char* const kVertexShader = R"(#version 120
attribute vec3 a_position;
attribute vec3 a_normal;
uniform mat4 u_clip_from_world;
varying vec3 v_normal;
void main() {
  v_normal = a_normal;
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
}
)";

// render::ShadeSurface's kLambert: albedo * (ambient + key_radiance * max(N.L, 0)).
const char* const kFragmentShader = R"(#version 120
uniform vec3 u_key_dir;
uniform vec3 u_key_radiance;
uniform vec3 u_ambient;
uniform vec3 u_albedo;
varying vec3 v_normal;
void main() {
  float n_dot_l = max(dot(normalize(v_normal), u_key_dir), 0.0);
  gl_FragColor = vec4(u_albedo * (u_ambient + u_key_radiance * n_dot_l), 1.0);
}
)";

// Compiles and links; returns 0 and sets `error` on failure.
GLuint MakeProgram(std::string& error) {
  const auto compile = [&error](GLenum type, const char* source) -> GLuint {
    const GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
      char log[1024] = {};
      glGetShaderInfoLog(shader, sizeof(log), nullptr, log);
      error = std::string("shader compile: ") + log;
      return 0;
    }
    return shader;
  };
  const GLuint vs = compile(GL_VERTEX_SHADER, kVertexShader);
  const GLuint fs = compile(GL_FRAGMENT_SHADER, kFragmentShader);
  if (vs == 0 || fs == 0) return 0;
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glBindAttribLocation(program, 0, "a_position");
  glBindAttribLocation(program, 1, "a_normal");
  glLinkProgram(program);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    char log[1024] = {};
    glGetProgramInfoLog(program, sizeof(log), nullptr, log);
    error = std::string("program link: ") + log;
    return 0;
  }
  return program;
}

int LlvmpipeThreads() {
  const char* value = std::getenv("LP_NUM_THREADS");
  return value == nullptr ? -1 : std::atoi(value);
}

void BM_LlvmpipeBody(benchmark::State& state) {
  static const bench::BodyMesh body = bench::MakeBody();
  const int width = static_cast<int>(state.range(0));
  const int height = static_cast<int>(state.range(1));
  const bool per_vertex = state.range(3) != 0;
  const auto pixel_count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);

  // The colour buffer OSMesa renders into, and the buffer the pixels are read back into.
  std::vector<std::uint8_t> framebuffer(pixel_count * 4);
  std::vector<std::uint8_t> pixels(pixel_count * 4);
  OSMesaContext context = OSMesaCreateContextExt(OSMESA_RGBA, 24, 0, 0, nullptr);
  if (context == nullptr) {
    state.SkipWithError("OSMesaCreateContextExt failed");
    return;
  }
  if (!OSMesaMakeCurrent(context, framebuffer.data(), GL_UNSIGNED_BYTE, width, height)) {
    OSMesaDestroyContext(context);
    state.SkipWithError("OSMesaMakeCurrent failed");
    return;
  }
  std::string error;
  const GLuint program = MakeProgram(error);
  if (program == 0) {
    OSMesaDestroyContext(context);
    state.SkipWithError(error.c_str());
    return;
  }

  const render::Camera camera = bench::BodyCamera(width, height);
  const glm::mat4 clip_from_world = camera.ClipFromWorld();
  const render::ShadingContext lights = render::MakeShadingContext(
      render::LightRig{}, render::LightingModel::kLambert, camera.ViewFromWorld());
  const glm::vec3 albedo = render::SceneMesh{}.base_color;
  if (per_vertex) {
    // Fixed-function lighting (Gouraud): the same Lambert terms per vertex.
    // GL's light 0 is given in eye space, like the rig's view-space key light.
    const render::LightRig rig;
    const glm::vec4 key_dir_view(glm::normalize(rig.key.direction_view), 0.0f);
    const glm::vec4 key_radiance(lights.key_radiance, 1.0f), ambient(lights.ambient, 1.0f);
    const glm::vec4 material(albedo, 1.0f), black(0.0f, 0.0f, 0.0f, 1.0f);
    glMatrixMode(GL_PROJECTION);
    glLoadMatrixf(glm::value_ptr(camera.ClipFromView()));
    glMatrixMode(GL_MODELVIEW);
    glLoadIdentity();
    glLightfv(GL_LIGHT0, GL_POSITION, glm::value_ptr(key_dir_view));
    glLightfv(GL_LIGHT0, GL_DIFFUSE, glm::value_ptr(key_radiance));
    glLightfv(GL_LIGHT0, GL_AMBIENT, glm::value_ptr(black));
    glLightfv(GL_LIGHT0, GL_SPECULAR, glm::value_ptr(black));
    glLightModelfv(GL_LIGHT_MODEL_AMBIENT, glm::value_ptr(ambient));
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT_AND_DIFFUSE, glm::value_ptr(material));
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, glm::value_ptr(black));
    glEnable(GL_LIGHTING);
    glEnable(GL_LIGHT0);
    glLoadMatrixf(glm::value_ptr(camera.ViewFromWorld()));
  }
  glUseProgram(program);
  glUniformMatrix4fv(glGetUniformLocation(program, "u_clip_from_world"), 1, GL_FALSE,
                     glm::value_ptr(clip_from_world));
  glUniform3fv(glGetUniformLocation(program, "u_key_dir"), 1, glm::value_ptr(lights.key_dir));
  glUniform3fv(glGetUniformLocation(program, "u_key_radiance"), 1,
               glm::value_ptr(lights.key_radiance));
  glUniform3fv(glGetUniformLocation(program, "u_ambient"), 1, glm::value_ptr(lights.ambient));
  glUniform3fv(glGetUniformLocation(program, "u_albedo"), 1, glm::value_ptr(albedo));
  if (per_vertex) glUseProgram(0);

  const auto vertex_bytes = static_cast<GLsizeiptr>(body.positions.size() * sizeof(glm::vec3));
  GLuint buffers[3] = {};
  glGenBuffers(3, buffers);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  glBufferData(GL_ARRAY_BUFFER, vertex_bytes, nullptr, GL_STREAM_DRAW);
  if (per_vertex) {
    glVertexPointer(3, GL_FLOAT, 0, nullptr);
    glEnableClientState(GL_VERTEX_ARRAY);
  } else {
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(0);
  }
  glBindBuffer(GL_ARRAY_BUFFER, buffers[1]);
  glBufferData(GL_ARRAY_BUFFER, vertex_bytes, nullptr, GL_STREAM_DRAW);
  if (per_vertex) {
    glNormalPointer(GL_FLOAT, 0, nullptr);
    glEnableClientState(GL_NORMAL_ARRAY);
  } else {
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(1);
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[2]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(body.triangles.size() * sizeof(glm::uvec3)),
               body.triangles.data(), GL_STATIC_DRAW);
  const auto index_count = static_cast<GLsizei>(body.triangles.size() * 3);

  glViewport(0, 0, width, height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glEnable(GL_CULL_FACE);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  const glm::vec3 clear = render::BackgroundColor(render::Background{}, 0.5f);
  glClearColor(clear.r, clear.g, clear.b, 1.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);

  const auto draw_frame = [&] {
    glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
    glBufferSubData(GL_ARRAY_BUFFER, 0, vertex_bytes, body.positions.data());
    glBindBuffer(GL_ARRAY_BUFFER, buffers[1]);
    glBufferSubData(GL_ARRAY_BUFFER, 0, vertex_bytes, body.normals.data());
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  };
  // Untimed warm-up: llvmpipe compiles (LLVM JIT) its shader and state
  // variants on the first draws of every new context, tens of ms each; the
  // benchmark calls this function (a new context) for each of its runs.
  for (int i = 0; i < 3; ++i) draw_frame();

  for (auto _ : state) {
    draw_frame();
    benchmark::DoNotOptimize(pixels.data());
    benchmark::ClobberMemory();
  }
  if (const GLenum gl_error = glGetError(); gl_error != GL_NO_ERROR) {
    state.SkipWithError(("GL error " + std::to_string(gl_error)).c_str());
  }

  // Not timed: coverage from the depth buffer, and the optional snapshot.
  std::vector<float> depth(pixel_count);
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  const auto covered = std::count_if(depth.begin(), depth.end(), [](float d) { return d < 1.0f; });
  const char* renderer_name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  state.SetLabel(renderer_name != nullptr ? renderer_name : "?");
  if (const std::string path = bench::SnapshotPath(
          "llvmpipe_" + std::to_string(width) + "x" + std::to_string(height) +
          (per_vertex ? "_per_vertex" : ""));
      !path.empty()) {
    std::vector<std::uint8_t> rgb;
    rgb.reserve(pixel_count * 3);
    for (int y = height - 1; y >= 0; --y) {  // GL rows are bottom-up
      const std::uint8_t* row = pixels.data() + static_cast<std::size_t>(y) * 4 *
                                                    static_cast<std::size_t>(width);
      for (int x = 0; x < width; ++x) rgb.insert(rgb.end(), row + 4 * x, row + 4 * x + 3);
    }
    if (!bench::WritePpm(path, width, height, rgb)) state.SkipWithError("snapshot");
  }

  glDeleteBuffers(3, buffers);
  glDeleteProgram(program);
  OSMesaDestroyContext(context);

  state.counters["triangles"] = static_cast<double>(body.triangles.size());
  state.counters["coverage"] = static_cast<double>(covered) / static_cast<double>(pixel_count);
  state.counters["threads"] = static_cast<double>(LlvmpipeThreads());
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
  state.SetItemsProcessed(state.iterations());
}

}  // namespace

int main(int argc, char** argv) {
  // Before any context exists: llvmpipe reads it once, at screen creation.
  if (std::getenv("LP_NUM_THREADS") == nullptr) setenv("LP_NUM_THREADS", "1", 1);
  const int threads = LlvmpipeThreads();
  benchmark::RegisterBenchmark("BM_LlvmpipeBody", BM_LlvmpipeBody)
      ->ArgNames({"w", "h", "threads", "per_vertex"})
      ->ArgsProduct({{1280}, {720}, {threads}, {0, 1}})
      ->ArgsProduct({{1920}, {1080}, {threads}, {0, 1}})
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
