// The scene model: what a scene file (SCENE.md, docs/scene.md) describes,
// as plain Def structs with their documented defaults. The XML reader
// (reader.h) only fills these; building plants, terrain and particle
// systems from them is the scene builder's work.
//
// Units: metres, seconds, kilograms, degrees. Y is up, right-handed.
// Colours are linear RGB (files hold sRGB; the reader converts once).
// Every Def remembers where it was written (`loc`), so an error found
// later (a grammar that fails to parse, a simulation that explodes) names
// the scene's line.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostic.h"
#include "core/math.h"

namespace sylva::scene {

struct CameraDef {
  SourceLoc loc;
  // Either position + target, or orbit (azimuth, elevation in degrees,
  // distance in metres) around target.
  std::optional<Vec3> position;
  Vec3 target = Vec3::Zero();
  std::optional<Vec3> orbit;  // (azimuth, elevation, distance)
  Vec3 up = Vec3::UnitY();
  double fovDegrees = 40;  // vertical
  std::optional<double> near, far;
};

enum class LightType { kSun, kAmbient, kPoint };

struct LightDef {
  SourceLoc loc;
  LightType type = LightType::kSun;
  Vec3 direction = Vec3(-0.4, -1, -0.3);  // the way the light travels (sun)
  Vec3 position = Vec3::Zero();           // point lights
  Vec3 color = Vec3::Ones();              // linear
  double intensity = 1;
};

struct SkyDef {
  SourceLoc loc;
  Vec3 top = Vec3(0.16, 0.33, 0.62);      // linear
  Vec3 horizon = Vec3(0.62, 0.72, 0.83);  // linear
};

enum class NoiseKind { kFbm, kRidged, kDiamondSquare, kFlat };

struct TerrainDef {
  SourceLoc loc;
  std::string id;
  Vec2 size = Vec2(100, 100);  // x and z extent, centred on the origin
  int resolution = 257;        // vertices per side
  double height = 10;          // noise amplitude (flat: 0)
  NoiseKind noise = NoiseKind::kFbm;
  int octaves = 6;
  double lacunarity = 2;
  double gain = 0.5;
  std::optional<uint64_t> seed;         // absent: from the scene's seed and the element's id
  Vec3 color = Vec3(0.19, 0.26, 0.11);  // linear
};

struct Define {
  std::string name;
  double value = 0;
  SourceLoc loc;
};

struct PlantDef {
  SourceLoc loc;
  std::string id;
  std::string grammar;  // resolved against the scene file's folder
  SourceLoc grammarLoc;
  std::optional<int> steps;
  std::optional<uint64_t> seed;
  Vec3 position = Vec3::Zero();
  bool positionHasY = false;  // false: y is the terrain's surface at x, z
  double rotateDegrees = 0;   // about Y
  double scale = 1;
  // Grammar units vary (ABOP's trees are hundreds of units tall): when set,
  // the plant is first scaled to this height in metres, then by `scale`.
  std::optional<double> height;
  std::vector<Define> defines;
};

struct ForestDef {
  SourceLoc loc;
  std::string id;
  std::string grammar;
  SourceLoc grammarLoc;
  int count = 0;
  std::string on;                      // terrain id; empty: the ground plane
  Vec4 area = Vec4(-10, -10, 10, 10);  // x0 z0 x1 z1
  double minDistance = 0;              // 0: chosen from count and area
  int variants = 8;
  Vec2 scale = Vec2(0.8, 1.2);   // uniform scale drawn in this range
  std::optional<double> height;  // each variant scaled to this height (metres) first
  std::optional<int> steps;
  std::optional<uint64_t> seed;  // absent: from the scene's seed and the element's id
  std::vector<Define> defines;
};

enum class EmitterShape { kPoint, kSphere, kBox, kDisc, kTerrain, kPlant };
enum class PlantPart { kLeaves, kTips, kSegments };

struct EmitterDef {
  SourceLoc loc;
  std::string id;
  EmitterShape shape = EmitterShape::kPoint;
  Vec3 at = Vec3::Zero();
  Vec3 size = Vec3::Zero();  // full extent (sphere, disc: x is the diameter)
  std::string of;            // terrain or plant id
  PlantPart part = PlantPart::kTips;
  double rate = 0;  // per second
  uint64_t burst = 0;
  Vec3 direction = Vec3::UnitY();
  double speed = 0;
  double spreadDegrees = 0;  // half-angle of the cone about direction
  Vec2 lifetime = Vec2(2, 3);
  double mass = 1;
  double radius = 0.01;
};

enum class ForceKind { kGravity, kDrag, kAttractor, kVortex, kNoise };
enum class Falloff { kInverseSquare, kLinear };

struct ForceDef {
  SourceLoc loc;
  std::string id;
  ForceKind kind = ForceKind::kGravity;
  Vec3 g = Vec3(0, -9.81, 0);  // gravity
  double k = 0;                // drag, N s/m (quadratic: N s^2/m^2)
  bool quadratic = false;
  std::optional<Vec3> position;  // attractor, vortex centre
  std::string of;                // attractor at another element
  double strength = 1;
  Falloff falloff = Falloff::kInverseSquare;
  double radius = 0;  // attractor: no force inside this radius (0: none)
  Vec3 axis = Vec3::UnitY();
  double scale = 1;      // noise: spatial scale, metres
  double frequency = 1;  // noise: Hz
};

struct CollideDef {
  SourceLoc loc;
  std::string id;
  std::vector<std::string> with;  // terrain, plant, forest, cloth ids or `ground`
  SourceLoc withLoc;
  double restitution = 0.3;
  double friction = 0.2;
  bool stick = false;
};

enum class SpringTopology { kChain, kGrid, kNearest };

struct SpringsDef {
  SourceLoc loc;
  SpringTopology between = SpringTopology::kChain;
  double k = 100, damping = 1;
  std::optional<double> rest;  // absent: the distance at creation
};

struct OnDeathDef {
  SourceLoc loc;
  std::string emit;  // id of another particles element
  int count = 0;
};

enum class DrawAs { kPoints, kSprites, kMesh, kTrails };
enum class Blend { kAlpha, kAdditive };

struct DrawDef {
  SourceLoc loc;
  DrawAs as = DrawAs::kPoints;
  std::string mesh;  // `~name` (a grammar surface) or an .obj file
  double size = 0.05;
  Vec3 color = Vec3::Ones();
  std::optional<Vec3> colorEnd;  // colour over age: color -> colorEnd
  double alpha = 1;
  Blend blend = Blend::kAlpha;
  double spinDegrees = 0;  // tumbling, degrees per second
};

enum class Integrator { kSymplectic, kEuler, kRk2, kRk4, kRk45, kImplicit };

struct ParticlesDef {
  SourceLoc loc;
  std::string id;
  uint64_t max = 100000;
  Integrator integrator = Integrator::kSymplectic;
  int substeps = 1;
  bool wind = true;
  std::vector<EmitterDef> emitters;
  std::vector<ForceDef> forces;
  std::vector<CollideDef> collides;
  std::vector<SpringsDef> springs;
  std::optional<double> selfCollideRestitution;
  std::vector<OnDeathDef> onDeath;
  DrawDef draw;
};

enum class Pin { kTop, kLeft, kCorners, kNone, kIds };
enum class ClothSolver { kXpbd, kImplicit };

struct ClothDef {
  SourceLoc loc;
  std::string id;
  Vec2 size = Vec2(1, 1);
  int columns = 32, rows = 32;   // vertices across the width, down the height
  Vec3 position = Vec3::Zero();  // top-left corner
  Vec3 rotateDegrees = Vec3::Zero();
  Pin pin = Pin::kTop;
  std::vector<int> pinIds;
  ClothSolver solver = ClothSolver::kXpbd;
  double stretch = 1e4, bend = 1, damping = 0.01;
  Vec3 color = Vec3(0.6, 0.05, 0.05);
  bool wind = true;
  std::vector<ForceDef> forces;
  std::vector<CollideDef> collides;
};

struct FlockDef {
  SourceLoc loc;
  std::string id;
  int count = 100;
  Vec3 boundsMin = Vec3(-10, 0, -10), boundsMax = Vec3(10, 10, 10);
  double speed = 3;
  double cohesion = 1, separation = 1.5, alignment = 1;
  std::vector<std::string> avoid;
  SourceLoc avoidLoc;
  bool wind = true;
  std::vector<ForceDef> forces;
  DrawDef draw;
};

struct WindDef {
  SourceLoc loc;
  Vec3 velocity = Vec3::Zero();
  double gust = 0;         // noise amplitude, m/s
  double scale = 10;       // noise spatial scale, metres
  double frequency = 0.2;  // Hz
};

struct SimulationDef {
  SourceLoc loc;
  double fps = 30;
  int substeps = 4;
  double duration = 10;
  int threads = 0;  // 0: all cores
};

struct Scene {
  std::string path;  // the root file
  int version = 1;
  uint64_t seed = 1;
  std::map<std::string, std::string> parameters;  // name -> value, after -D
  std::optional<CameraDef> camera;
  std::vector<LightDef> lights;
  std::optional<SkyDef> sky;
  std::vector<TerrainDef> terrains;
  std::vector<PlantDef> plants;
  std::vector<ForestDef> forests;
  std::vector<ParticlesDef> particles;
  std::vector<ClothDef> cloths;
  std::vector<FlockDef> flocks;
  std::optional<WindDef> wind;
  SimulationDef simulation;
  std::vector<std::string> files;  // every file read (root, includes)
};

}  // namespace sylva::scene
