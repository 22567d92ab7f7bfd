// A scenario: everything that defines a world, scalar-independent and exact. Numbers are kept
// as exact fractions (Rational) so every scalar rounds the scenario's decimal text exactly once.
// The JSON format is documented in docs/scenario-format.md.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/math/rational.h"
#include "sim/math/scalar.h"
#include "sim/terrain/heightmap.h"

namespace sg {

using Rational3 = std::array<Rational, 3>;

/// How a tuft moves (docs/grass-models.md). Every model keeps the tip on its rod of length L.
enum class GrassModel : uint8_t {
  Thesis,  ///< position projected, velocity untouched (Cyclone, as in the thesis)
  Pbd,     ///< position-based dynamics: velocity recomputed from the corrected position
  Blade,   ///< a stiff blade: recovery toward the upright rest pose, gravity, trampling
};
/// "thesis", "pbd" or "blade": the JSON name of a grass model.
inline const char* grassModelName(GrassModel m) {
  return m == GrassModel::Blade ? "blade" : m == GrassModel::Pbd ? "pbd" : "thesis";
}
/// Which row a gust reaches first.
enum class WindTravel : uint8_t {
  Direction,  ///< a gust enters from the side it blows from (+z gusts: first row first)
  Forward,    ///< every gust travels +z (what the thesis code did: its loop order had no effect)
};

/// Rigid-body primitives (thesis §4: sphere and box; compounds are lists of them).
enum class ShapeType : uint8_t { Sphere, Box };
/// Which particles the body-particle stage tests against a body (results are identical).
enum class ParticleBroadphase : uint8_t { Grid, Brute };
/// Which body pairs the body-body stage tests (results are identical).
enum class BodyBroadphase : uint8_t { Brute, SweepAndPrune };
/// What a body's push does to a grass tip (models thesis and pbd; the blade model always holds).
enum class TipContact : uint8_t {
  Push,  ///< thesis: the position moves out of the body, nothing else
  Hold,  ///< as a contact: back to its rod's length, a vertical push bends it, no velocity into the body
};
/// The push direction for a particle inside a box.
enum class BoxParticleNormal : uint8_t {
  Up,           ///< thesis: constant (0, 1, 0); the particle is pushed down, towards the ground
  NearestFace,  ///< out through the nearest face
};

struct ShapeSpec {
  ShapeType type = ShapeType::Sphere;
  Rational radius{1, 2};                                                  ///< m (sphere)
  Rational3 halfExtents{Rational{1, 2}, Rational{1, 2}, Rational{1, 2}};  ///< m (box)
  Rational3 offset{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};       ///< m, in the body frame
};

struct BodySpec {
  std::string name;
  std::vector<ShapeSpec> parts;  ///< one for a sphere or a box; several for a compound
  bool compound = false;         ///< written as a compound (error paths: .shape.parts[k], not .shape)
  Rational mass{1, 1};           ///< kg
  Rational3 position{Rational{0, 1}, Rational{1, 1}, Rational{0, 1}};
  std::array<Rational, 4> orientation{Rational{1, 1}, Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};  ///< w, x, y, z
  Rational3 velocity{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  Rational3 angularVelocity{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  Rational linearDamping{1, 1};  ///< per-second velocity factor
  Rational angularDamping{1, 1};
  Rational restitution{3, 10};
  Rational friction{1, 2};
  bool mower = false;    ///< cuts the grass it touches
  bool canSleep = true;  ///< may sleep when it has been still for a while (thesis: "ability to sleep")
  /// Optional OBJ file for the renderer's looks only (as written in the JSON, relative to the
  /// scenario file's directory); never affects the simulation or the state hash.
  std::string mesh;
};

/// One scripted command (the scenario's input track).
enum class BodyCommandKind : uint8_t {
  Displace,     ///< position += value (thesis "direct position change")
  AddVelocity,  ///< velocity += value (thesis "velocity movement")
  Impulse,      ///< velocity += value / mass
  Teleport,     ///< position = value, velocities = 0
  Reset,        ///< back to the scenario start state (position, orientation, rest); value ignored
  Spawn,        ///< append a new body: a copy of body `body`'s spec at value (m), at rest,
                ///< with the template's initial orientation; at most kMaxBodies, else ignored
  MowerOn,      ///< a mower's blade cuts again (mowers start on); ignored for other bodies
  MowerOff,     ///< a mower's blade stops cutting (the body still collides); ignored for others
  DragTo,       ///< a spring (settings::kDragHertz) pulls the centre of mass toward value (m) for
                ///< this tick: the viewer's mouse drag, one command a tick while the button is held
};
/// A Spawn while the world holds this many bodies or more is ignored (a scenario may list up to
/// 1,024 bodies; then nothing spawns, and commands may name every listed one: bodyIndexLimit).
inline constexpr int kMaxBodies = 64;
/// The largest tick anything may name or run to: ticks are below 2^40 (a script command's or
/// camera key's tick, an input track's length, a command line's --ticks, --to, --hash-every).
/// 2^40 ticks at 1/60 s are 580 years; the bound keeps tick arithmetic far from int64 overflow.
inline constexpr int64_t kMaxTick = (int64_t(1) << 40) - 1;
/// Body indices a world of `listedBodies` can hold: 0 .. max(listed, kMaxBodies) - 1 (a list
/// longer than the spawn limit leaves no room to spawn, but its own bodies are all addressable).
/// What a script, an input track and a recording's INPT may name, and what a state may hold.
inline int64_t bodyIndexLimit(size_t listedBodies) {
  return listedBodies > size_t(kMaxBodies) ? int64_t(listedBodies) : int64_t(kMaxBodies);
}
/// A camera key of a camera track: the camera sits at `position` from `tick` until the next key.
struct CameraKey {
  int64_t tick = 0;
  Rational3 position{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
};

/// Level of detail (thesis §3): simulate only a window of the meadow around the camera.
enum class LodMode : uint8_t { Off, Window };

struct ScriptedCommand {
  int64_t tick = 0;
  int32_t body = 0;
  BodyCommandKind kind = BodyCommandKind::AddVelocity;
  Rational3 value{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}};
  /// Its index in the JSON array it was read from ($.script[source] or $.commands[source]): the
  /// array is sorted by tick, so messages name this, not the position after sorting.
  int64_t source = 0;
};

struct WindGust {
  Rational3 force;    ///< N (mass 1: m/s^2)
  Rational duration;  ///< s
  /// The horizontal direction (x, z) its front travels in, any length but not zero; absent: along
  /// z as wind.travel says (the thesis' rows). docs/scenario-format.md, sim/wind/wind.h.
  std::optional<std::array<Rational, 2>> front = std::nullopt;
};

struct Scenario {
  std::string name = "thesis-meadow";
  uint64_t seed = 1;
  ScalarKind scalar = ScalarKind::Fx32;
  Rational timeStep{1, 60};  ///< s per tick

  struct Field {
    int64_t patchesX = 151, patchesZ = 151;
    Rational spacing{1, 4};                 ///< m between patch centres
    Rational jitter{3, 10};                 ///< max |offset| as a fraction of spacing
    Rational centerX{0, 1}, centerZ{0, 1};  ///< m, world position of the field centre
    Rational scaleY{1, 1};                  ///< m, tuft quad height (mScaleY)
    Rational scaleXZ{1, 2};                 ///< m, tuft quad half width (mScaleXZ)
    int atlasVariants = 4;
  } field;

  struct Particles {
    int interpolation = 1;            ///< k: one particle per k x k patches
    Rational constraintLength{1, 1};  ///< m, rod length L
    /// m/s (model blade: 0 unless given)
    Rational3 initialVelocity{Rational{1, 5}, Rational{1, 5}, Rational{1, 5}};
    /// m/s^2: thesis and pbd lift the tuft by 1 m/s^2 (the thesis' value); model blade defaults
    /// to gravity, (0, -9.81, 0), its stiffness holding it up
    Rational3 acceleration{Rational{0, 1}, Rational{1, 1}, Rational{0, 1}};
    Rational mass{1, 1};        ///< kg
    Rational damping{97, 100};  ///< velocity factor per second (v *= damping^dt); model blade: 1 unless given
    /// JSON "model" ("constraintMode" in files written before the blade model; thesis or pbd).
    GrassModel model = GrassModel::Thesis;
    /// The model the scenario text gives (a variant may change `model`, not this): recordings
    /// name the model in their variant when it is not thesis or not what the text says.
    GrassModel writtenModel = GrassModel::Thesis;
    /// The blade model's constants (model "blade" only; docs/grass-models.md), as a user thinks of
    /// a blade: how fast it sways and how quickly that dies away, in still air. The world derives
    /// the recovery stiffness (2 pi frequency)^2 - acceleration.y / L (1/s^2) and the damping rate
    /// 4 pi dampingRatio frequency (1/s) from them, exactly (pi as a fraction good to 1e-16).
    struct Blade {
      Rational frequency{1, 2};      ///< Hz: small sways under the scenario's acceleration
      Rational dampingRatio{3, 10};  ///< of critical: 0.3 rings down to 5 % in about 1.6 periods
      /// s: a pressed blade loses its stiffness and regains it linearly over this time (0: no
      /// trampling). Under gravity it lies down until its stiffness carries its weight again.
      Rational trampleSeconds{10, 1};
    } blade;
    /// Tilt brightness thresholds: level n when the tip sinks more than tiltDrop[n-1] below L.
    std::array<Rational, 3> tiltDrop{Rational{1, 5}, Rational{3, 10}, Rational{2, 5}};
  } particles;

  struct Wind {
    Rational travelSpeed{15, 2};  ///< m/s at which a gust front crosses the rows
    WindTravel travel = WindTravel::Direction;
    std::vector<WindGust> schedule = {
        {{Rational{0, 1}, Rational{1, 1}, Rational{9, 10}}, Rational{5, 1}},
        {{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}}, Rational{6, 1}},
        {{Rational{0, 1}, Rational{1, 1}, Rational{-9, 10}}, Rational{4, 1}},
        {{Rational{0, 1}, Rational{0, 1}, Rational{0, 1}}, Rational{6, 1}},
    };
  } wind;

  struct Terrain {
    bool flat = true;
    Rational flatHeight{0, 1};  ///< m
    std::string heightmapPath;  ///< as written in the scenario (relative to the scenario file)
    Heightmap heightmap;
    Rational cellSize{1, 1};                ///< m between heightmap samples
    Rational maxHeight{5, 1};               ///< m at sample value 255
    Rational centerX{0, 1}, centerZ{0, 1};  ///< m, world position of the heightmap centre
  } terrain;

  struct Bodies {
    Rational3 gravity{Rational{0, 1}, Rational{-981, 100}, Rational{0, 1}};  ///< m/s^2
    /// The soft step (sim/collision/contact_solver.h): sub-steps per tick (4, as Box2D v3), and
    /// solve and relax sweeps per sub-step (3 and 1: with Box2D's 1 solve sweep a 20-box stack
    /// falls, docs/physics-notes.md).
    int substeps = 4;
    int velocityIterations = 3;  ///< solve sweeps per sub-step of a body alone (its terrain contacts)
    /// Solve sweeps per sub-step of an island of touching bodies (at least velocityIterations):
    /// Gauss-Seidel carries a correction across one contact per sweep, and a heavy or wide load on a
    /// lighter support rocked for ever at 3 (docs/physics-notes.md).
    int islandVelocityIterations = 6;
    int positionIterations = 1;  ///< relax sweeps per sub-step (0: the push velocity stays)
    /// Hz: the soft contacts' spring (Box2D's contactHertz), capped at a quarter of the sub-step
    /// rate; the terrain's is twice it. The default is the cap at 60 Hz ticks and 4 sub-steps;
    /// tall stacks without sleep need stiffer (docs/physics-notes.md).
    Rational contactHertz{60, 1};
    ParticleBroadphase particleBroadphase = ParticleBroadphase::Grid;
    BodyBroadphase bodyBroadphase = BodyBroadphase::Brute;
    BoxParticleNormal boxParticleNormal = BoxParticleNormal::Up;
    /// Models thesis and pbd (docs/grass-models.md "Bodies in every model"): the thesis' push
    /// leaves tips inside a body that rests on them; `hold` keeps them out.
    TipContact tipContact = TipContact::Push;
    Rational mowerCutHeight{1, 5};  ///< m above the ground: where a mower's blade cuts the tufts
    /// Grass drag on bodies, N s/m per tuft pushed this tick (0: off, the thesis model): each
    /// pushed tuft resists the body's motion, v *= 1 - min(1, drag * tufts * dt / m).
    Rational grassDrag{0, 1};
    std::vector<BodySpec> list;
  } bodies;

  /// A football field painted with white tufts (thesis §5): lines of `lineWidth` along the
  /// boundary, the halfway line and the centre circle; length along x, width along z.
  struct Markings {
    bool enabled = false;
    Rational centerX{0, 1}, centerZ{0, 1};
    Rational length{30, 1}, width{20, 1}, lineWidth{1, 2}, centerCircleRadius{3, 1};
  } markings;
  std::vector<ScriptedCommand> script;  ///< sorted by tick, then body
  std::vector<CameraKey> camera;        ///< scripted camera track, increasing ticks

  /// Level of detail. Off: the whole field is simulated. Window: W x H particles around the
  /// camera (level 0), a static edge-grass ring of `edgeRows` rows at `edgeSpacing` x the grass
  /// spacing around it (level 1), the terrain beyond (level 2). docs/level-of-detail.md.
  struct Lod {
    LodMode mode = LodMode::Off;
    int64_t windowX = 151, windowZ = 151;  ///< particles (clamped to the field)
    bool centerGiven = false;
    Rational centerX{0, 1}, centerZ{0, 1};  ///< m, where the window starts (default: the field centre)
    int edgeSpacing = 4;                    ///< edge-grass spacing as a multiple of the grass spacing
    int edgeRows = 30;
  } lod;

  std::string sourceName = "<built-in>";  ///< file name for error messages
  std::string text;                       ///< the JSON text it was parsed from
};

/// A bad scenario: names the file, the JSON path and what was expected.
class ScenarioError : public std::runtime_error {
 public:
  ScenarioError(const std::string& file, const std::string& path, const std::string& expected);
  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }

 private:
  std::string file_, path_;
};

/// Reads the bytes of a file named in a scenario (the heightmap), relative to the scenario.
/// Returns false with *error set ("file 'x.png' not found") when it cannot.
using ScenarioFileReader =
    std::function<bool(const std::string& path, std::vector<uint8_t>* bytes, std::string* error)>;

/// Parses and validates a scenario. Throws ScenarioError. Unknown keys are errors; missing keys
/// take the thesis defaults above.
Scenario parseScenario(const std::string& text, const std::string& sourceName, const ScenarioFileReader& readFile);

/// An input-track file (docs/scenario-format.md): camera keys and body commands that replace a
/// scenario's script when recording. Commands name bodies of `scenario` and use the script's
/// schema; the camera holds each key's position until the next key.
struct InputTrack {
  std::string sourceName;                 ///< file name for error messages
  std::optional<int64_t> ticks;           ///< how long to record, when the track says
  std::vector<CameraKey> camera;          ///< increasing ticks
  std::vector<ScriptedCommand> commands;  ///< sorted by tick
};
/// Throws ScenarioError (file, JSON path, expected) like parseScenario. Values are checked against
/// scenario.scalar (validateInputTrack): apply variants to the scenario before parsing the track.
InputTrack parseInputTrack(const std::string& text, const std::string& sourceName, const Scenario& scenario);

/// The thesis meadow, embedded (identical to scenarios/thesis-meadow.json).
const std::string& defaultScenarioText();

/// Checks that the scenario fits the chosen scalar (coordinates, resolution) and a memory
/// budget. Throws ScenarioError naming the offending JSON path.
void validateForScalar(const Scenario& scenario, ScalarKind scalar, uint64_t memoryLimitBytes);

/// Checks every camera position and command value of an input track against a scalar: each must
/// fit Q32.32 (inputs are recorded so) and the scalar's range, a position its coordinate range.
/// Throws ScenarioError naming the track file and the JSON path ($.commands[i].value[c]).
void validateInputTrack(const InputTrack& track, ScalarKind scalar);

/// Bytes of world state a scenario needs with a scalar (used by the memory check): the field's
/// patches and particles, the level-of-detail edge ring, the heightmap and its derived terrain.
uint64_t estimateWorldBytes(const Scenario& scenario, ScalarKind scalar);

/// The largest heightmap side accepted (samples along x or z): a 4096 x 4096 heightmap is 16 M
/// samples. Checked by parseScenario right after the PNG is decoded (docs/scenario-format.md).
inline constexpr int kMaxHeightmapSide = 4096;

}  // namespace sg
