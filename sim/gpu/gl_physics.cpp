#include "sim/gpu/gl_physics.h"

#include <GL/glew.h>

#include <cstring>
#include <type_traits>

#include "sim/gpu/osmesa_host.h"
#include "sim/gpu/particle_pass_glsl.h"

namespace sg::gpu {
namespace {

/// The headless context every device of one provider shares.
struct ComputeContext {
  void* context = nullptr;  ///< OSMesaContext
  unsigned char buffer[4 * 4 * 4] = {};
  std::string description;
  void makeCurrent() { makeOsmesaContextCurrent(context, buffer, 4); }
  ~ComputeContext() { destroyOsmesaContext(context); }
};

std::string glString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "?";
}

/// Compiles and links one compute program; 0 with *error set (the driver's log) on failure.
GLuint buildProgram(const std::string& source, std::string* error) {
  const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    *error = std::string("GPU physics: the particle pass does not compile: ") + log;
    glDeleteShader(shader);
    return 0;
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, shader);
  glLinkProgram(program);
  glDeleteShader(shader);
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[4096] = {};
    glGetProgramInfoLog(program, sizeof log, nullptr, log);
    *error = std::string("GPU physics: the particle pass does not link: ") + log;
    glDeleteProgram(program);
    return 0;
  }
  return program;
}

// Shader storage bindings (particle_pass_glsl.h).
enum Binding : GLuint { kPositionIn, kVelocityIn, kPositionOut, kVelocityOut, kAnchor, kDisplacement, kTick, kFault };

/// One world's particles in shader storage buffers, and the pass over them. Positions and
/// velocities are double-buffered: a pass reads set `current_` and writes the other, which
/// becomes current only when the pass did not fault.
template <class S>
class GlParticleDevice final : public ParticleDevice<S> {
  using Raw = typename S::RawType;
  static_assert(sizeof(S) == sizeof(Raw) && std::is_trivially_copyable_v<S>, "Fixed is its raw value");

 public:
  GlParticleDevice(std::shared_ptr<ComputeContext> context, GLuint program, int64_t countX, int64_t countZ)
      : context_(std::move(context)), program_(program), countX_(countX), countZ_(countZ) {
    glCreateBuffers(2, position_);
    glCreateBuffers(2, velocity_);
    glCreateBuffers(1, &anchor_);
    glCreateBuffers(1, &displacement_);
    glCreateBuffers(1, &tickBuffer_);
    glCreateBuffers(1, &fault_);
    for (GLuint b : {position_[0], position_[1], velocity_[0], velocity_[1], anchor_, displacement_})
      glNamedBufferData(b, 3 * arrayBytes(), nullptr, GL_DYNAMIC_COPY);
    glNamedBufferData(tickBuffer_, GLsizeiptr(4 + 3 * countZ) * GLsizeiptr(sizeof(Raw)), nullptr, GL_STREAM_DRAW);
    glNamedBufferData(fault_, sizeof(GLuint), nullptr, GL_STREAM_READ);
    tick_.resize(size_t(4 + 3 * countZ));
    countXLocation_ = glGetUniformLocation(program_, "countX");
    countLocation_ = glGetUniformLocation(program_, "count");
  }
  ~GlParticleDevice() override {  // the program is the provider's
    context_->makeCurrent();
    for (GLuint b :
         {position_[0], position_[1], velocity_[0], velocity_[1], anchor_, displacement_, tickBuffer_, fault_})
      glDeleteBuffers(1, &b);
  }
  GlParticleDevice(const GlParticleDevice&) = delete;
  GlParticleDevice& operator=(const GlParticleDevice&) = delete;

  bool ok() const { return glGetError() == GL_NO_ERROR; }

  void upload(const ParticleArrays<S>& p) override {
    context_->makeCurrent();
    put(position_[current_], {&p.px, &p.py, &p.pz});
    put(velocity_[current_], {&p.vx, &p.vy, &p.vz});
    put(anchor_, {&p.anchorX, &p.anchorY, &p.anchorZ});
  }

  RowFault advance(const std::vector<S>& dvx, const std::vector<S>& dvy, const std::vector<S>& dvz,
                   const ParticleConstants<S>& c, uint32_t* faultBits) override {
    context_->makeCurrent();
    tick_[0] = c.dt.raw();
    tick_[1] = c.dampingPerTick.raw();
    tick_[2] = c.rodLength.raw();
    tick_[3] = c.invDt.raw();
    for (int64_t r = 0; r < countZ_; ++r) {
      tick_[size_t(4 + 3 * r)] = dvx[size_t(r)].raw();
      tick_[size_t(5 + 3 * r)] = dvy[size_t(r)].raw();
      tick_[size_t(6 + 3 * r)] = dvz[size_t(r)].raw();
    }
    glNamedBufferSubData(tickBuffer_, 0, GLsizeiptr(tick_.size() * sizeof(Raw)), tick_.data());
    const GLuint none = 0xFFFFFFFFu;
    glNamedBufferSubData(fault_, 0, sizeof none, &none);
    glUseProgram(program_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPositionIn, position_[current_]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kVelocityIn, velocity_[current_]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kPositionOut, position_[1 - current_]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kVelocityOut, velocity_[1 - current_]);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kAnchor, anchor_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kDisplacement, displacement_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kTick, tickBuffer_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, kFault, fault_);
    const int64_t n = countX_ * countZ_;
    glUniform1ui(countXLocation_, GLuint(countX_));
    glUniform1ui(countLocation_, GLuint(n));
    glDispatchCompute(GLuint((n + 255) / 256), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    // The one value every tick reads back: whether (and where) the pass faulted, which step()
    // must report at this tick.
    GLuint key = none;
    glGetNamedBufferSubData(fault_, 0, sizeof key, &key);
    *faultBits = 0;
    if (key == none) {
      current_ = 1 - current_;
      return {};
    }
    *faultBits = kFixedFaultOverflow;  // the only fault the pass can raise (no d = 0 division, no negative root)
    const int64_t row = int64_t(key) / (2 * countX_), rest = int64_t(key) % (2 * countX_);
    const bool projection = rest >= countX_;
    return {row * countX_ + (projection ? rest - countX_ : rest), projection ? Stage::Constraints : Stage::Integrate};
  }

  void download(ParticleArrays<S>& p, std::vector<S>* dx, std::vector<S>* dy, std::vector<S>* dz) override {
    context_->makeCurrent();
    get(position_[current_], {&p.px, &p.py, &p.pz});
    get(velocity_[current_], {&p.vx, &p.vy, &p.vz});
    if (dx) get(displacement_, {dx, dy, dz});
  }

 private:
  GLsizeiptr arrayBytes() const { return GLsizeiptr(countX_ * countZ_) * GLsizeiptr(sizeof(Raw)); }
  void put(GLuint buffer, std::initializer_list<const std::vector<S>*> arrays) {
    GLintptr at = 0;
    for (const std::vector<S>* a : arrays) {
      glNamedBufferSubData(buffer, at, arrayBytes(), a->data());
      at += arrayBytes();
    }
  }
  void get(GLuint buffer, std::initializer_list<std::vector<S>*> arrays) {
    GLintptr at = 0;
    for (std::vector<S>* a : arrays) {
      glGetNamedBufferSubData(buffer, at, arrayBytes(), a->data());
      at += arrayBytes();
    }
  }

  std::shared_ptr<ComputeContext> context_;
  GLuint program_ = 0;
  GLuint position_[2] = {}, velocity_[2] = {}, anchor_ = 0, displacement_ = 0, tickBuffer_ = 0, fault_ = 0;
  int current_ = 0;  ///< which position and velocity set holds the state
  GLint countXLocation_ = -1, countLocation_ = -1;
  int64_t countX_ = 0, countZ_ = 0;
  std::vector<Raw> tick_;
};

class OsmesaPhysicsProvider final : public ParticleDeviceProvider {
 public:
  explicit OsmesaPhysicsProvider(std::shared_ptr<ComputeContext> context) : context_(std::move(context)) {}
  ~OsmesaPhysicsProvider() override {
    context_->makeCurrent();
    for (auto& byModel : programs_)
      for (GLuint p : byModel)
        if (p) glDeleteProgram(p);
  }

  std::unique_ptr<ParticleDevice<Fx32>> makeFx32(int64_t countX, int64_t countZ, bool pbd,
                                                 std::string* error) override {
    return make<Fx32>(countX, countZ, pbd, error);
  }
  std::unique_ptr<ParticleDevice<Fx16>> makeFx16(int64_t countX, int64_t countZ, bool pbd,
                                                 std::string* error) override {
    return make<Fx16>(countX, countZ, pbd, error);
  }
  std::string describe() const override { return context_->description; }

 private:
  template <class S>
  std::unique_ptr<ParticleDevice<S>> make(int64_t countX, int64_t countZ, bool pbd, std::string* error) {
    context_->makeCurrent();
    const int64_t n = countX * countZ;
    GLint64 maxBlock = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
    const int64_t blockBytes = 3 * n * int64_t(sizeof(S));  // x, y and z in one buffer
    if (n <= 0 || n >= (int64_t(1) << 30) || blockBytes > int64_t(maxBlock)) {
      *error = "GPU physics: " + std::to_string(n) + " particles need " + std::to_string(blockBytes) +
               "-byte storage buffers; this device allows " + std::to_string(int64_t(maxBlock));
      return nullptr;
    }
    // One program per format and constraint mode, compiled on first use and kept.
    GLuint& program = programs_[std::is_same_v<S, Fx32> ? 0 : 1][pbd ? 1 : 0];
    if (!program) {
      const std::string prelude = std::string("#version 450\n#extension GL_ARB_gpu_shader_int64 : require\n") +
                                  "#define FX32 " + (std::is_same_v<S, Fx32> ? "1" : "0") + "\n#define PBD " +
                                  (pbd ? "1" : "0") + "\n";
      program = buildProgram(prelude + kParticlePassGlsl, error);
      if (!program) return nullptr;
    }
    while (glGetError() != GL_NO_ERROR) {
    }
    auto device = std::make_unique<GlParticleDevice<S>>(context_, program, countX, countZ);
    if (!device->ok()) {
      *error = "GPU physics: the device could not allocate buffers for " + std::to_string(n) + " particles";
      return nullptr;
    }
    return device;
  }

  std::shared_ptr<ComputeContext> context_;
  GLuint programs_[2][2] = {};  ///< [fx32, fx16][thesis, pbd]
};

}  // namespace

std::unique_ptr<ParticleDeviceProvider> makeOsmesaPhysicsProvider(std::string* error) {
  auto context = std::make_shared<ComputeContext>();
  context->context = createOsmesaCoreContext(4, 5, 0, context->buffer, 4, error);
  if (!context->context) return nullptr;
  if (!GLEW_ARB_compute_shader || !GLEW_ARB_gpu_shader_int64 || !GLEW_ARB_gpu_shader_fp64 ||
      !GLEW_ARB_direct_state_access) {
    *error = "GPU physics: the OpenGL context (" + glString(GL_RENDERER) +
             ") lacks compute shaders, 64-bit integers, doubles or direct state access";
    return nullptr;
  }
  context->description = "OpenGL " + glString(GL_VERSION) + " compute on " + glString(GL_RENDERER);
  return std::make_unique<OsmesaPhysicsProvider>(std::move(context));
}

}  // namespace sg::gpu
