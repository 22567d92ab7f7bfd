#include "sim/gpu/gl_physics.h"

#include <GL/glew.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <functional>
#include <type_traits>

#include "sim/gpu/particle_pass_glsl.h"

namespace sg::gpu {
namespace {

/// The context every device of one provider shares (GlContextHooks): its own headless one, or
/// whatever context is current when the provider is made and used (a renderer's, which then
/// draws straight from the devices' buffers).
struct ComputeContext {
  GlContextHooks hooks;
  std::string description;
  void makeCurrent() {
    if (hooks.makeCurrent) hooks.makeCurrent();
  }
  ~ComputeContext() {
    if (hooks.destroy) hooks.destroy();
  }
};

std::string glString(GLenum name) {
  const auto* s = reinterpret_cast<const char*>(glGetString(name));
  return s ? s : "?";
}

/// The most work groups one dispatch may have along x (GL guarantees 65,535).
int64_t maxWorkGroups() {
  GLint groups = 0;
  glGetIntegeri_v(GL_MAX_COMPUTE_WORK_GROUP_COUNT, 0, &groups);
  return groups > 0 ? int64_t(groups) : 65535;
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
enum Binding : GLuint {
  kPositionIn,
  kVelocityIn,
  kPositionOut,
  kVelocityOut,
  kAnchor,
  kDisplacement,
  kTick,
  kFault,
  kRuns,
  kTrampleIn,
  kTrampleOut
};
// The push pass's bindings (kPushPassGlsl).
enum PushBinding : GLuint {
  kPushPosition,
  kPushVelocity,
  kPushAnchor,
  kPushTrample,
  kPushFault,
  kPushCandidates,
  kPushBackup,
  kPushValues,
  kPushInts,
  kPushCounts
};
// The patch pass's bindings (kPatchPassGlsl).
enum PatchBinding : GLuint {
  kPatchDisplacement,
  kPatchConstants,
  kPatchRootY,
  kPatchCut,
  kPatchOut,
  kPatchDraw,
  kPatchTrample
};

/// What a value of S is stored as in the buffers: a fixed-point value is its raw integer, a float
/// itself.
template <class S>
struct Stored {
  using Type = typename S::RawType;
  static Type of(S v) { return v.raw(); }
  static S value(Type r) { return S::fromRaw(r); }
};
template <>
struct Stored<float> {
  using Type = float;
  static float of(float v) { return v; }
  static float value(float r) { return r; }
};

/// One world's particles in shader storage buffers, and the pass over them. Positions,
/// velocities and trample levels are double-buffered: a pass reads set `current_` and writes the
/// other, which becomes current only when the pass did not fault.
template <class S>
class GlParticleDevice final : public ParticleDevice<S> {
  using Raw = typename Stored<S>::Type;
  static_assert(sizeof(S) == sizeof(Raw) && std::is_trivially_copyable_v<S>, "a value is stored as itself");

 public:
  /// `pushProgram` compiles (once, kept by the provider) the bodies' push pass.
  GlParticleDevice(std::shared_ptr<ComputeContext> context, GLuint program, std::function<GLuint()> pushProgram,
                   GLuint patchProgram, int64_t countX, int64_t countZ, bool tramples)
      : context_(std::move(context)),
        program_(program),
        makePushProgram_(std::move(pushProgram)),
        patchProgram_(patchProgram),
        countX_(countX),
        countZ_(countZ),
        tramples_(tramples) {
    for (GLuint* b : buffers()) glCreateBuffers(1, b);
    for (GLuint b : {position_[0], position_[1], velocity_[0], velocity_[1], anchor_, displacement_})
      glNamedBufferData(b, 3 * arrayBytes(), nullptr, GL_DYNAMIC_COPY);
    for (GLuint b : trample_) glNamedBufferData(b, tramples ? arrayBytes() : 16, nullptr, GL_DYNAMIC_COPY);
    for (GLuint b : {pushValues_, pushInts_, pushCounts_, candidates_, backup_})
      glNamedBufferData(b, 16, nullptr, GL_STREAM_DRAW);
    glNamedBufferData(fault_, sizeof(GLuint), nullptr, GL_STREAM_READ);
  }
  ~GlParticleDevice() override {  // the program is the provider's
    context_->makeCurrent();
    for (GLuint* b : buffers()) glDeleteBuffers(1, b);
  }
  GlParticleDevice(const GlParticleDevice&) = delete;
  GlParticleDevice& operator=(const GlParticleDevice&) = delete;

  bool ok() const { return glGetError() == GL_NO_ERROR; }

  void upload(const ParticleArrays<S>& p) override {
    context_->makeCurrent();
    put(position_[current_], {&p.px, &p.py, &p.pz});
    put(velocity_[current_], {&p.vx, &p.vy, &p.vz});
    put(anchor_, {&p.anchorX, &p.anchorY, &p.anchorZ});
    if (tramples_) put(trample_[current_], {&p.trample});
  }

  bool push(const DevicePush<S>& push) override {
    context_->makeCurrent();
    const GLuint parts = packPush(push);
    if (parts == 0) return candidateList_.empty();  // no candidate: nothing to push; else too many here
    if (!pushProgram_) pushProgram_ = makePushProgram_();
    if (!pushProgram_) return false;  // it did not compile: the host pushes (GlPhysicsProvider::make)
    const GLuint none = 0xFFFFFFFFu;
    glNamedBufferSubData(fault_, 0, sizeof none, &none);
    traffic_.toDevice += sizeof none;
    runPushPass(parts, false);
    // Whether a push faulted: the response stage must report it at this tick, before the drag.
    GLuint key = none;
    glGetNamedBufferSubData(fault_, 0, sizeof key, &key);
    traffic_.toHost += sizeof key;
    if (key != none) {  // the state as the push found it, for the host to push
      runPushPass(parts, true);
      return false;
    }
    if (push.pushedPerBody) {  // the grass drag's tuft counts
      pushCountWords_.resize(push.bodyCount);
      glGetNamedBufferSubData(pushCounts_, 0, GLsizeiptr(push.bodyCount * sizeof(GLuint)), pushCountWords_.data());
      traffic_.toHost += GLsizeiptr(push.bodyCount * sizeof(GLuint));
      push.pushedPerBody->assign(pushCountWords_.begin(), pushCountWords_.end());
    }
    return true;
  }

  RowFault advance(const DeviceWind<S>& wind, const ParticleConstants<S>& c, uint32_t* faultBits) override {
    context_->makeCurrent();
    const size_t runCount = wind.runBegin.size();
    using St = Stored<S>;
    tick_.assign({St::of(c.dt), St::of(c.dampingPerTick), St::of(c.rodLength), St::of(c.invDt),
                  St::of(c.bladeStiffnessDt), St::of(c.bladeDampingPerTick), St::of(c.trampleDecayPerTick),
                  St::of(c.invRodLength)});
    for (size_t k = 0; k < runCount; ++k) {
      tick_.push_back(St::of(wind.dvx[k]));
      tick_.push_back(St::of(wind.dvy[k]));
      tick_.push_back(St::of(wind.dvz[k]));
    }
    runs_.assign(wind.rowFirstRun.begin(), wind.rowFirstRun.end());
    for (int64_t r = 0; r < countZ_; ++r) {  // each run as [begin, end)
      const int32_t first = wind.rowFirstRun[size_t(r)], end = wind.rowFirstRun[size_t(r) + 1];
      for (int32_t k = first; k < end; ++k) {
        runs_.push_back(wind.runBegin[size_t(k)]);
        runs_.push_back(k + 1 < end ? wind.runBegin[size_t(k) + 1] : int32_t(countX_));
      }
    }
    replaceContents(tickBuffer_, tick_, &tickCapacity_);
    replaceContents(runBuffer_, runs_, &runCapacity_);
    const GLuint none = 0xFFFFFFFFu;
    glNamedBufferSubData(fault_, 0, sizeof none, &none);
    traffic_.toDevice += GLsizeiptr(tick_.size() * sizeof(Raw) + runs_.size() * sizeof(int32_t) + sizeof none);
    glUseProgram(program_);
    const GLuint next = 1 - current_;
    const std::pair<Binding, GLuint> bindings[] = {{kPositionIn, position_[current_]},
                                                   {kVelocityIn, velocity_[current_]},
                                                   {kPositionOut, position_[next]},
                                                   {kVelocityOut, velocity_[next]},
                                                   {kAnchor, anchor_},
                                                   {kDisplacement, displacement_},
                                                   {kTick, tickBuffer_},
                                                   {kFault, fault_},
                                                   {kRuns, runBuffer_},
                                                   {kTrampleIn, trample_[current_]},
                                                   {kTrampleOut, trample_[next]}};
    for (const auto& [binding, buffer] : bindings) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    const int64_t n = countX_ * countZ_;
    glUniform1ui(glGetUniformLocation(program_, "countX"), GLuint(countX_));
    glUniform1ui(glGetUniformLocation(program_, "countZ"), GLuint(countZ_));
    glUniform1ui(glGetUniformLocation(program_, "count"), GLuint(n));
    glDispatchCompute(GLuint((n + 255) / 256), 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    // The one value every tick reads back: whether (and where) the pass faulted, which step()
    // must report at this tick.
    GLuint key = none;
    glGetNamedBufferSubData(fault_, 0, sizeof key, &key);
    traffic_.toHost += sizeof key;
    *faultBits = 0;
    if (key == none) {
      current_ = next;
      return {};
    }
    // The only fixed-point fault the pass can raise (no d = 0 division, no negative root); a float
    // pass faults on a value that is not finite or beyond +-2^48, which has no fault bits.
    *faultBits = std::is_same_v<S, float> ? 0u : uint32_t(kFixedFaultOverflow);
    return decode(key, wind);
  }

  void uploadCells(const ParticleArrays<S>& p, const std::vector<typename ParticleDevice<S>::Span>& spans) override {
    context_->makeCurrent();
    for (const auto& s : spans) {
      const Span cells{s.first, s.count};
      put(position_[current_], {&p.px, &p.py, &p.pz}, cells);
      put(velocity_[current_], {&p.vx, &p.vy, &p.vz}, cells);
      put(anchor_, {&p.anchorX, &p.anchorY, &p.anchorZ}, cells);
      if (tramples_) put(trample_[current_], {&p.trample}, cells);
    }
  }

  void download(ParticleArrays<S>& p, std::vector<S>* dx, std::vector<S>* dy, std::vector<S>* dz) override {
    context_->makeCurrent();
    get(position_[current_], {&p.px, &p.py, &p.pz});
    get(velocity_[current_], {&p.vx, &p.vy, &p.vz});
    if (tramples_) get(trample_[current_], {&p.trample});
    if (dx) get(displacement_, {dx, dy, dz});
  }

  bool derivePatches(const DevicePatchInputs<S>& in) override {
    context_->makeCurrent();
    const int64_t patchCount = in.patches.size();
    if (!patchesFit_) return false;
    if (patchCount != patchCount_) {  // the window's size is fixed: allocated once per world
      // Each output array set is one storage block, as the particles' are (GlPhysicsProvider::make).
      GLint64 maxBlock = 0;
      glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
      patchesFit_ = 4 * patchCount * int64_t(sizeof(Raw)) <= int64_t(maxBlock) &&
                    patchCount * int64_t(4 * sizeof(float)) <= int64_t(maxBlock) && patchCount <= 256 * maxWorkGroups();
      patchCount_ = patchCount;
      if (!patchesFit_) return false;
      glNamedBufferData(rootY_, patchCount * GLsizeiptr(sizeof(Raw)), nullptr, GL_DYNAMIC_DRAW);
      glNamedBufferData(cut_, patchCount * GLsizeiptr(sizeof(GLuint)), nullptr, GL_DYNAMIC_DRAW);
      glNamedBufferData(patchOut_, 4 * patchCount * GLsizeiptr(sizeof(Raw)), nullptr, GL_DYNAMIC_COPY);
      for (GLuint b : patchDraw_)
        glNamedBufferData(b, patchCount * GLsizeiptr(4 * sizeof(float)), nullptr, GL_DYNAMIC_COPY);
      patchRevision_ = 0;
    }
    const PatchStateConstants<S>& c = *in.constants;
    using St = Stored<S>;
    patchConstants_.assign({St::of(c.halfRod), St::of(c.scaleY), St::of(c.cutReduction), St::of(c.minimumTop),
                            St::of(c.drop[0]), St::of(c.drop[1]), St::of(c.drop[2])});
    for (const S& w : c.weight) patchConstants_.push_back(St::of(w));
    replaceContents(patchConstantBuffer_, patchConstants_, &patchConstantCapacity_);
    traffic_.toDevice += GLsizeiptr(patchConstants_.size() * sizeof(Raw));
    if (in.revision != patchRevision_) {  // a window move, a cut, a restore
      patchRevision_ = in.revision;
      static_assert(sizeof(S) == sizeof(Raw));
      glNamedBufferSubData(rootY_, 0, patchCount * GLsizeiptr(sizeof(Raw)), in.rootY->data());
      cutWords_.assign(in.cut->begin(), in.cut->end());
      glNamedBufferSubData(cut_, 0, patchCount * GLsizeiptr(sizeof(GLuint)), cutWords_.data());
      traffic_.toDevice += patchCount * GLsizeiptr(sizeof(Raw) + sizeof(GLuint));
    }
    glUseProgram(patchProgram_);
    drawCurrent_ ^= 1u;  // the other draw buffer: the last one keeps the state it was derived from
    const std::pair<PatchBinding, GLuint> bindings[] = {{kPatchDisplacement, displacement_},
                                                        {kPatchConstants, patchConstantBuffer_},
                                                        {kPatchRootY, rootY_},
                                                        {kPatchCut, cut_},
                                                        {kPatchOut, patchOut_},
                                                        {kPatchDraw, patchDraw_[drawCurrent_]},
                                                        {kPatchTrample, trample_[current_]}};
    for (const auto& [binding, buffer] : bindings) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    const auto window = [](const LatticeWindow& w) {
      return std::array<GLint, 4>{GLint(w.originI), GLint(w.originJ), GLint(w.sizeI), GLint(w.sizeJ)};
    };
    const GLuint p = patchProgram_;
    glUniform1i(glGetUniformLocation(p, "k"), GLint(c.k));
    glUniform4iv(glGetUniformLocation(p, "particleWindow"), 1, window(in.particles).data());
    glUniform4iv(glGetUniformLocation(p, "patchWindow"), 1, window(in.patches).data());
    glUniform2i(glGetUniformLocation(p, "patchStorageOrigin"), GLint(in.patches.storageColumn(in.patches.originI)),
                GLint(in.patches.storageRow(in.patches.originJ)));
    glUniform1ui(glGetUniformLocation(p, "patchCount"), GLuint(patchCount));
    glUniform1ui(glGetUniformLocation(p, "particleCount"), GLuint(countX_ * countZ_));
    glUniform1i(glGetUniformLocation(p, "tramples"), tramples_ ? 1 : 0);
    glDispatchCompute(GLuint((patchCount + 255) / 256), 1, 1);
    // A renderer reads the draw copy as a vertex attribute or a buffer texture.
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT |
                    GL_TEXTURE_FETCH_BARRIER_BIT);
    return true;
  }

  void downloadPatches(PatchArrays<S>& patches) override {
    context_->makeCurrent();
    std::vector<Raw> out(size_t(4 * patchCount_));
    glGetNamedBufferSubData(patchOut_, 0, GLsizeiptr(out.size() * sizeof(Raw)), out.data());
    traffic_.toHost += GLsizeiptr(out.size() * sizeof(Raw));
    const size_t n = size_t(patchCount_);
    for (size_t q = 0; q < n; ++q) {
      patches.tipOffsetX[q] = Stored<S>::value(out[q]);
      patches.tipOffsetZ[q] = Stored<S>::value(out[n + q]);
      patches.topY[q] = Stored<S>::value(out[2 * n + q]);
      patches.tiltLevel[q] = uint8_t(out[3 * n + q]);
    }
  }

  uint32_t patchDrawBuffer() const override { return patchCount_ > 0 && patchesFit_ ? patchDraw_[drawCurrent_] : 0; }
  DeviceTraffic traffic() const override { return traffic_; }

 private:
  /// Particles [first, first + count) of every array of a buffer.
  struct Span {
    int64_t first = 0, count = -1;  ///< count < 0: all
  };
  GLsizeiptr arrayBytes() const { return GLsizeiptr(countX_ * countZ_) * GLsizeiptr(sizeof(Raw)); }
  /// The arrays of one buffer (x, y, z one after the other), or the span of each.
  void put(GLuint buffer, std::initializer_list<const std::vector<S>*> arrays, Span span = {}) {
    const int64_t count = span.count < 0 ? countX_ * countZ_ : span.count;
    GLintptr at = GLintptr(span.first) * GLintptr(sizeof(Raw));
    for (const std::vector<S>* a : arrays) {
      glNamedBufferSubData(buffer, at, GLsizeiptr(count) * GLsizeiptr(sizeof(Raw)), a->data() + span.first);
      at += arrayBytes();
      traffic_.toDevice += GLsizeiptr(count) * GLsizeiptr(sizeof(Raw));
    }
  }
  void get(GLuint buffer, std::initializer_list<std::vector<S>*> arrays, Span span = {}) {
    const int64_t count = span.count < 0 ? countX_ * countZ_ : span.count;
    GLintptr at = GLintptr(span.first) * GLintptr(sizeof(Raw));
    for (std::vector<S>* a : arrays) {
      glGetNamedBufferSubData(buffer, at, GLsizeiptr(count) * GLsizeiptr(sizeof(Raw)), a->data() + span.first);
      at += arrayBytes();
      traffic_.toHost += GLsizeiptr(count) * GLsizeiptr(sizeof(Raw));
    }
  }

  /// Replaces a per-tick buffer's contents, growing it when the tick holds more (gust fronts
  /// split rows into runs).
  template <class T>
  static void replaceContents(GLuint buffer, const std::vector<T>& values, GLsizeiptr* capacity) {
    const GLsizeiptr bytes = GLsizeiptr(values.size() * sizeof(T));
    if (bytes > *capacity) {
      *capacity = std::max<GLsizeiptr>(bytes, 2 * *capacity);
      glNamedBufferData(buffer, *capacity, nullptr, GL_STREAM_DRAW);
    }
    glNamedBufferSubData(buffer, 0, bytes, values.data());
  }
  /// The push pass over this tick's candidates (packPush), or, with `restore`, the candidates'
  /// state put back as the push found it.
  void runPushPass(GLuint pushParts, bool restore) {
    const GLuint p = pushProgram_;
    glUseProgram(p);
    const std::pair<PushBinding, GLuint> bindings[] = {{kPushPosition, position_[current_]},
                                                       {kPushVelocity, velocity_[current_]},
                                                       {kPushAnchor, anchor_},
                                                       {kPushTrample, trample_[current_]},
                                                       {kPushFault, fault_},
                                                       {kPushCandidates, candidates_},
                                                       {kPushBackup, backup_},
                                                       {kPushValues, pushValues_},
                                                       {kPushInts, pushInts_},
                                                       {kPushCounts, pushCounts_}};
    for (const auto& [binding, buffer] : bindings) glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    const GLuint count = GLuint(candidateList_.size());
    glUniform1ui(glGetUniformLocation(p, "countX"), GLuint(countX_));
    glUniform1ui(glGetUniformLocation(p, "count"), GLuint(countX_ * countZ_));
    glUniform1ui(glGetUniformLocation(p, "candidates"), count);
    glUniform1ui(glGetUniformLocation(p, "restore"), restore ? 1u : 0u);
    glUniform1ui(glGetUniformLocation(p, "pushParts"), pushParts);
    glUniform1ui(glGetUniformLocation(p, "pushFlags"), pushFlags_);
    glDispatchCompute((count + 255) / 256, 1, 1);  // count <= particles: within make()'s bound
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  }

  /// Packs this tick's pushers for the push pass (kPushPassGlsl) into the push buffers, with the
  /// candidates (each storage row's particles in a column range of a part over it, in row and
  /// column order), clears the per-body counts where they are kept and sets pushFlags_; returns
  /// the number of parts, 0 when there is nothing to push (no candidate) or the candidates'
  /// backup would not fit one storage block (the candidates stay listed: the host pushes).
  GLuint packPush(const DevicePush<S>& push) {
    const GrassPushers<S>& pushers = *push.pushers;
    const BodyParticleSettings<S>& settings = *push.settings;
    const size_t parts = pushers.parts.size();
    candidateList_.clear();
    if (parts == 0) return 0;
    using St = Stored<S>;
    pushValueData_.assign({St::of(settings.pushAllowance), St::of(settings.rodLength)});
    pushIntData_.clear();
    for (const GrassPusher<S>& p : pushers.parts) {
      const Vec3<S>& c = p.pose.position;
      for (int a = 0; a < 3; ++a) pushValueData_.push_back(St::of(c[a]));
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) pushValueData_.push_back(St::of(p.pose.rotation(r, k)));
      const bool sphere = p.shape->type == ShapeType::Sphere;
      for (int a = 0; a < 3; ++a)
        pushValueData_.push_back(St::of(sphere ? (a == 0 ? p.shape->radius : S(0)) : p.shape->halfExtents[a]));
      pushValueData_.push_back(St::of(p.share));
      pushValueData_.push_back(St::of(p.candidateReach));
      pushIntData_.insert(pushIntData_.end(), {sphere ? 0 : 1, p.body, int32_t(p.firstColumn),
                                               int32_t(std::max<int64_t>(0, p.range.a1 - p.range.a0 + 1))});
    }
    // Each storage row's part list (the bucket of its lattice row), after the row bounds; and the
    // row's candidates, the union of its parts' column ranges.
    const size_t lists = pushIntData_.size();
    pushIntData_.resize(lists + size_t(countZ_) + 1);
    candidateList_.clear();
    columnTaken_.assign(size_t(countX_), 0);
    for (int64_t r = 0; r < countZ_; ++r) {
      pushIntData_[lists + size_t(r)] = int32_t(pushIntData_.size());
      const int64_t b = push.window->latticeRow(r) - pushers.originJ;
      const size_t firstCandidate = candidateList_.size();
      for (int64_t k = pushers.rowStart[size_t(b)]; k < pushers.rowStart[size_t(b + 1)]; ++k) {
        const GrassPusher<S>& part = pushers.parts[size_t(pushers.byRow[size_t(k)])];
        pushIntData_.push_back(pushers.byRow[size_t(k)]);
        const int64_t columns = std::min(countX_, part.range.a1 - part.range.a0 + 1);
        for (int64_t t = 0, c = part.firstColumn; t < columns; ++t, c = c + 1 == countX_ ? 0 : c + 1)
          if (!columnTaken_[size_t(c)]) {
            columnTaken_[size_t(c)] = 1;
            candidateList_.push_back(GLuint(r * countX_ + c));
          }
      }
      std::sort(candidateList_.begin() + std::ptrdiff_t(firstCandidate), candidateList_.end());
      for (size_t q = firstCandidate; q < candidateList_.size(); ++q) columnTaken_[candidateList_[q] % countX_] = 0;
    }
    pushIntData_[lists + size_t(countZ_)] = int32_t(pushIntData_.size());
    if (candidateList_.empty()) return 0;
    GLint64 maxBlock = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
    const GLsizeiptr backupBytes = GLsizeiptr(7 * candidateList_.size() * sizeof(Raw));
    if (backupBytes > maxBlock) return 0;
    if (backupBytes > backupCapacity_) {
      backupCapacity_ = std::min<GLsizeiptr>(std::max(backupBytes, 2 * backupCapacity_), GLsizeiptr(maxBlock));
      while (glGetError() != GL_NO_ERROR) {
      }
      glNamedBufferData(backup_, backupCapacity_, nullptr, GL_DYNAMIC_COPY);
      if (glGetError() != GL_NO_ERROR) {  // out of memory: the host pushes
        backupCapacity_ = 0;
        return 0;
      }
    }
    replaceContents(candidates_, candidateList_, &candidateCapacity_);
    traffic_.toDevice += GLsizeiptr(candidateList_.size() * sizeof(GLuint));
    replaceContents(pushValues_, pushValueData_, &pushValueCapacity_);
    replaceContents(pushInts_, pushIntData_, &pushIntCapacity_);
    traffic_.toDevice += GLsizeiptr(pushValueData_.size() * sizeof(Raw) + pushIntData_.size() * sizeof(int32_t));
    const bool counts = push.pushedPerBody != nullptr;
    if (counts) {
      const GLsizeiptr bytes = GLsizeiptr(std::max<size_t>(1, push.bodyCount) * sizeof(GLuint));
      if (bytes > pushCountCapacity_) {
        pushCountCapacity_ = std::max(bytes, 2 * pushCountCapacity_);
        glNamedBufferData(pushCounts_, pushCountCapacity_, nullptr, GL_STREAM_READ);
      }
      const GLuint zero = 0;
      glClearNamedBufferSubData(pushCounts_, GL_R32UI, 0, bytes, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    pushFlags_ = (settings.boxNormal == BoxParticleNormal::NearestFace ? 1u : 0u) | (settings.holdTips ? 2u : 0u) |
                 (settings.broadphase == ParticleBroadphase::Grid ? 4u : 0u) | (counts ? 8u : 0u);
    return GLuint(parts);
  }

  /// The particle and stage of fault key `key` (particle_pass_glsl.h): after the row's base
  /// row 2 countX, run k covers [2 begin_k, 2 end_k), integration faults before projection ones.
  RowFault decode(GLuint key, const DeviceWind<S>& wind) const {
    const int64_t row = int64_t(key) / (2 * countX_), rest = int64_t(key) % (2 * countX_);
    const int32_t first = wind.rowFirstRun[size_t(row)], end = wind.rowFirstRun[size_t(row) + 1];
    for (int32_t k = first; k < end; ++k) {
      const int64_t begin = wind.runBegin[size_t(k)];
      const int64_t stop = k + 1 < end ? int64_t(wind.runBegin[size_t(k) + 1]) : countX_;
      if (rest >= 2 * stop) continue;
      const int64_t offset = rest - 2 * begin;
      const bool projection = offset >= stop - begin;
      return {row * countX_ + begin + (projection ? offset - (stop - begin) : offset),
              projection ? Stage::Constraints : Stage::Integrate};
    }
    return {row * countX_, Stage::Integrate};  // unreachable: the runs cover the row
  }

  std::array<GLuint*, 22> buffers() {
    return {&position_[0], &position_[1],  &velocity_[0], &velocity_[1],  &trample_[0],   &trample_[1],
            &anchor_,      &displacement_, &tickBuffer_,  &runBuffer_,    &fault_,        &patchConstantBuffer_,
            &rootY_,       &cut_,          &patchOut_,    &patchDraw_[0], &patchDraw_[1], &pushValues_,
            &pushInts_,    &pushCounts_,   &candidates_,  &backup_};
  }

  std::shared_ptr<ComputeContext> context_;
  GLuint program_ = 0;
  std::function<GLuint()> makePushProgram_;
  GLuint patchProgram_ = 0, pushProgram_ = 0;
  GLuint position_[2] = {}, velocity_[2] = {};  ///< x, y and z in each
  GLuint trample_[2] = {};                      ///< 16 bytes each without trampling
  GLuint anchor_ = 0, displacement_ = 0;        ///< x, y and z in each
  GLuint tickBuffer_ = 0, runBuffer_ = 0, fault_ = 0;
  GLsizeiptr tickCapacity_ = 0, runCapacity_ = 0;
  GLuint current_ = 0;  ///< which position, velocity and trample set holds the state
  int64_t countX_ = 0, countZ_ = 0;
  bool tramples_ = false;
  std::vector<Raw> tick_;
  std::vector<int32_t> runs_;
  // The body pushes (packPush): values, integers, candidates, the candidates' state before the
  // push, and per-body counts, each tick that has pushers.
  GLuint pushValues_ = 0, pushInts_ = 0, pushCounts_ = 0, candidates_ = 0, backup_ = 0;
  GLsizeiptr pushValueCapacity_ = 0, pushIntCapacity_ = 0, pushCountCapacity_ = 0, candidateCapacity_ = 0,
             backupCapacity_ = 0;
  std::vector<GLuint> candidateList_;
  std::vector<uint8_t> columnTaken_;
  GLuint pushFlags_ = 0;
  std::vector<Raw> pushValueData_;
  std::vector<int32_t> pushIntData_;
  std::vector<GLuint> pushCountWords_;
  // The patch stage (derivePatches): per patch slot, the inputs (root height, cut flag as a
  // 32-bit word) copied when their revision changes, and the outputs.
  GLuint patchConstantBuffer_ = 0, rootY_ = 0, cut_ = 0, patchOut_ = 0;
  /// The draw copy, alternating between two buffers derive by derive: the last one's buffer keeps
  /// the state before it (a renderer interpolating between two ticks reads both).
  GLuint patchDraw_[2] = {};
  GLuint drawCurrent_ = 0;
  GLsizeiptr patchConstantCapacity_ = 0;
  int64_t patchCount_ = 0;
  bool patchesFit_ = true;      ///< the window's patches fit the device's storage blocks
  uint64_t patchRevision_ = 0;  ///< of the inputs on the device (0: none)
  std::vector<Raw> patchConstants_;
  std::vector<GLuint> cutWords_;
  DeviceTraffic traffic_;
};

class GlPhysicsProvider final : public ParticleDeviceProvider {
 public:
  explicit GlPhysicsProvider(std::shared_ptr<ComputeContext> context) : context_(std::move(context)) {}
  ~GlPhysicsProvider() override {
    context_->makeCurrent();
    for (auto& byModel : programs_)
      for (auto& byTrample : byModel)
        for (auto& byPush : byTrample)
          for (GLuint p : byPush)
            if (p) glDeleteProgram(p);
    for (GLuint p : patchPrograms_)
      if (p) glDeleteProgram(p);
  }

  std::unique_ptr<ParticleDevice<Fx32>> makeFx32(int64_t countX, int64_t countZ, GrassModel model, bool tramples,
                                                 std::string* error) override {
    return make<Fx32>(countX, countZ, model, tramples, error);
  }
  std::unique_ptr<ParticleDevice<Fx16>> makeFx16(int64_t countX, int64_t countZ, GrassModel model, bool tramples,
                                                 std::string* error) override {
    return make<Fx16>(countX, countZ, model, tramples, error);
  }
  std::unique_ptr<ParticleDevice<float>> makeFloat(int64_t countX, int64_t countZ, GrassModel model, bool tramples,
                                                   std::string* error) override {
    return make<float>(countX, countZ, model, tramples, error);
  }
  std::string describe() const override { return context_->description; }

 private:
  template <class S>
  std::unique_ptr<ParticleDevice<S>> make(int64_t countX, int64_t countZ, GrassModel model, bool tramples,
                                          std::string* error) {
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
    if (n > 256 * maxWorkGroups()) {  // one invocation a particle, 256 a work group
      *error = "GPU physics: " + std::to_string(n) + " particles need more than " + std::to_string(maxWorkGroups()) +
               " work groups, this device's most in one dispatch";
      return nullptr;
    }
    // One program per format, model and trampling, compiled on first use and kept.
    const int modelIndex = model == GrassModel::Pbd ? 1 : model == GrassModel::Blade ? 2 : 0;
    tramples = tramples && model == GrassModel::Blade;
    const int format = std::is_same_v<S, Fx32> ? 0 : std::is_same_v<S, Fx16> ? 1 : 2;
    GLuint(&programs)[2] = programs_[format][modelIndex][tramples ? 1 : 0];
    const std::string prelude = std::string("#version 450\n#extension GL_ARB_gpu_shader_int64 : require\n") +
                                "#define FX32 " + (format == 0 ? "1" : "0") + "\n#define FLOAT " +
                                (format == 2 ? "1" : "0") + "\n#define MODEL " + std::to_string(modelIndex) +
                                "\n#define TRAMPLE " + (tramples ? "1" : "0") + "\n";
    if (!programs[0]) {
      programs[0] = buildProgram(prelude + kScalarGlsl + kParticlePassGlsl, error);
      if (!programs[0]) return nullptr;
    }
    // The push pass, compiled when a tick first has pushers. A driver that cannot
    // compile it (none known) leaves the device's advance() reporting a fault at every tick with
    // pushers, so the CPU reference does those ticks: slow, never wrong.
    auto pushProgram = [context = context_, &cached = programs[1], source = prelude + kScalarGlsl + kPushPassGlsl]() {
      context->makeCurrent();
      std::string ignored;
      if (!cached) cached = buildProgram(source, &ignored);
      return cached;
    };
    GLuint& patchProgram = patchPrograms_[format];
    if (!patchProgram) {
      patchProgram = buildProgram(prelude + kScalarGlsl + kPatchPassGlsl, error);
      if (!patchProgram) return nullptr;
    }
    while (glGetError() != GL_NO_ERROR) {
    }
    auto device = std::make_unique<GlParticleDevice<S>>(context_, programs[0], std::move(pushProgram), patchProgram,
                                                        countX, countZ, tramples);
    if (!device->ok()) {
      *error = "GPU physics: the device could not allocate buffers for " + std::to_string(n) + " particles";
      return nullptr;
    }
    return device;
  }

  std::shared_ptr<ComputeContext> context_;
  GLuint programs_[3][3][2][2] = {};  ///< [fx32, fx16, float][thesis, pbd, blade][trample][particle, push pass]
  GLuint patchPrograms_[3] = {};      ///< [fx32, fx16, float]
};

/// A provider over `context` once it is current, or nullptr when it lacks what the passes need.
std::unique_ptr<ParticleDeviceProvider> providerOn(std::shared_ptr<ComputeContext> context, const char* whose,
                                                   std::string* error) {
  if (!GLEW_ARB_compute_shader || !GLEW_ARB_gpu_shader_int64 || !GLEW_ARB_gpu_shader_fp64 ||
      !GLEW_ARB_direct_state_access) {
    *error = "GPU physics: the OpenGL context (" + glString(GL_RENDERER) +
             ") lacks compute shaders, 64-bit integers, doubles or direct state access";
    return nullptr;
  }
  context->description = "OpenGL " + glString(GL_VERSION) + " compute on " + glString(GL_RENDERER) + whose;
  return std::make_unique<GlPhysicsProvider>(std::move(context));
}
}  // namespace

std::unique_ptr<ParticleDeviceProvider> makeGlPhysicsProvider(GlContextHooks hooks, const std::string& whose,
                                                              std::string* error) {
  auto context = std::make_shared<ComputeContext>();
  context->hooks = std::move(hooks);
  context->makeCurrent();
  return providerOn(std::move(context), whose.c_str(), error);
}

std::unique_ptr<ParticleDeviceProvider> makeCurrentContextPhysicsProvider(std::string* error) {
  return makeGlPhysicsProvider({}, ", the renderer's context", error);
}

}  // namespace sg::gpu
