// The in-memory description of a shot: pure data, filled by io/scene_reader from a
// scene file (and by tests directly). Units are SI, Y up, unless `units` says otherwise.
#pragma once
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sim/core/types.h"
#include "sim/scene/sdf_grid.h"
#include "sim/scene/shell_mesh.h"

namespace shellmpm {

/// The particle-grid transfer: quadratic B-spline APIC, or MLS-MPM (Hu et al. 2018).
enum class Transfer { Apic, Mls };

/// Accuracy presets (`shot.quality`, io/scene_quality.h): grid and sheet resolution
/// relative to the scene's, and CFL, quadrature, contact samples and particles per cell
/// where the scene does not set them. Chosen on the accuracy study's front (docs/accuracy.md).
enum class Quality { Draft, Preview, Production, Final };
/// Whether shells that share grid nodes share one velocity there (no-slip between them, as
/// in the paper) or each keeps its own (ShellFields; friction from contact only).
enum class ShellVelocities { PerShell, Shared };
/// Where grid contact between two bodies acts: where their contact surfaces meet (a
/// shell's limit surface offset by half its contact thickness, bulk material where its
/// particles' volume ends; sim/contact/contact_gap.h), or wherever their B-spline
/// stencils share a node (the paper's behaviour: bodies rest one to two cells apart).
enum class ContactAt { Surface, Stencil };

/// Shot-wide settings.
/// How a step advances: explicit (symplectic Euler, steps bounded by the fastest elastic
/// wave) or implicit (backward Euler by Newton's method, sim/implicit/; steps bounded by
/// motion, the frame and the Newton cap); auto: one of the two by the rule of
/// sim/solver/integrator_choice.h, resolved when the scene is read (a Solver never sees it).
enum class Integrator { Explicit, Implicit, Auto };
/// The implicit shell step's CG preconditioner (sim/implicit/shell_step.h).
enum class ImplicitPreconditioner { Factorised, BlockJacobi };

struct ShotSettings {
  int frame_start = 1;             ///< first frame written; frame f is the state at t = (f-1)/fps
  int frame_end = 48;              ///< last frame written, inclusive
  double fps = 24.0;               ///< frames per second
  double cfl = 0.3;                ///< CFL number: max particle travel per step, in cells
  double dt_min = 1e-6;            ///< smallest allowed step [s]; a smaller need is an error
  double dt_max = 1e-2;            ///< largest allowed step [s]
  Vec3d gravity{0.0, -9.81, 0.0};  ///< [m/s^2]
  Vec3d domain_min{-1, -1, -1};    ///< simulation domain; particles are kept inside [m]
  Vec3d domain_max{1, 1, 1};
  double dx = 0.02;  ///< grid spacing [m]
  int threads = 0;   ///< 0 = all cores
  Transfer transfer = Transfer::Apic;
  /// The accuracy preset the reader applied (io/scene_quality.h); none: values as written.
  std::optional<Quality> quality;
  ShellVelocities shell_velocities = ShellVelocities::PerShell;
  /// True: where two layers of one shell meet at a node they get two velocities there
  /// (sim/contact/shell_folds.cpp), so a fold slides over its own cloth at Coulomb's law;
  /// false: one (the fold drags; cheaper for a lone shell).
  bool fold_fields = true;
  /// Where grid contact acts (ContactAt): at the bodies' surfaces (the default), or the
  /// paper's cushion at the stencils.
  ContactAt contact_at = ContactAt::Surface;
  /// The shell guard (sim/contact/shell_guard.h): stops contact shells from closing
  /// closer than shell_guard_gap where the grid cannot hold them apart.
  bool shell_guard = true;
  double shell_guard_gap = 0;  ///< [m]; 0: ShellGuardStage::gap
  std::string units = "m";     ///< informational, written to VDB metadata
  Integrator integrator = Integrator::Explicit;
  /// shot.dt_max was given (else an implicit step's default is one frame, also when auto
  /// chooses implicit).
  bool dt_max_set = false;
  /// Why `auto` chose the integrator it did (resolve_integrator); empty otherwise.
  std::string integrator_reason;
  /// Implicit: a Newton solve has converged when no velocity correction it asks for
  /// exceeds this [m/s].
  double implicit_tolerance = 1e-4;
  int newton_max_iterations = 30;  ///< implicit: Newton iterations before a step is retried
  int cg_max_iterations = 500;     ///< implicit: CG iterations per Newton iteration
  ImplicitPreconditioner implicit_preconditioner = ImplicitPreconditioner::Factorised;
  /// Implicit shells without contact: the theta method's weight of the end-of-step forces
  /// (1: backward Euler, damps fast modes; 0.5: trapezoidal, damps nothing).
  double implicit_theta = 1;
  /// Implicit: denting plasticity inside the solve (each step minimises the return
  /// mapping's incremental potential: the solve sees the returned stress), or only after
  /// it (the solve sees the elastic trial stress).
  bool plasticity_in_solve = false;
  /// Implicit grid step: the shells' own velocity fields at shared nodes as unknowns of
  /// the solve (field_slots.h), or added after it.
  bool shell_fields_in_solve = false;
  /// Implicit grid step: Coulomb friction at the colliders inside the solve (a lagged
  /// potential, the step solved again with the normal impulses), or after it.
  bool friction_in_solve = false;
  /// With friction in the solve: the speed along a collider below which a node sticks
  /// elastically (friction_potential.h's eps) [m/s]; a node held by friction creeps at most
  /// this fast, and a larger one makes the solves easier.
  double friction_stick_speed = 1e-3;
  /// What a frame whose integrity check failed (material through a shell, shells crossing,
  /// points inside a collider, non-finite state) does: warn and go on, or stop (exit 1).
  enum class OnIntegrityFailure { Warn, Stop } on_integrity_failure = OnIntegrityFailure::Warn;
  /// What a frame that gained energy nothing supplied does (sim/integrity/energy_audit.h):
  /// nothing, warn and go on, or stop (exit 1).
  enum class OnEnergyGain { Ignore, Warn, Stop } on_energy_gain = OnEnergyGain::Warn;
};

enum class MaterialKind { Elastic, Sand, Snow };
enum class ElasticModel { FixedCorotated, NeoHookean };

/// A bulk MPM material.
struct MaterialDesc {
  std::string name;
  MaterialKind kind = MaterialKind::Elastic;
  ElasticModel model = ElasticModel::FixedCorotated;  ///< elastic only
  double youngs_modulus = 1e5;                        ///< E [Pa]
  double poisson_ratio = 0.3;                         ///< nu, in [0, 0.5)
  double density = 1000.0;                            ///< rest density [kg/m^3]
  // sand (Drucker-Prager on Hencky strain, Klar et al. 2016)
  double friction_angle_deg = 30.0;  ///< internal friction angle [degrees]
  double cohesion = 0.0;             ///< cohesion, as a Hencky-strain offset (>= 0)
  // snow (Stomakhin et al. 2013)
  double critical_compression = 2.5e-2;  ///< theta_c
  double critical_stretch = 7.5e-3;      ///< theta_s
  double hardening = 10.0;               ///< xi
  double max_hardening_jp_min = 0.6;     ///< clamp of Jp from below (keeps hardening finite)
  double max_hardening_jp_max = 20.0;    ///< clamp of Jp from above
  std::optional<Vec3d> color;            ///< preview colour (linear RGB); none: by kind
};

/// A shape used by sources and colliders.
struct ShapeDesc {
  enum class Kind { Plane, Box, Sphere, Cylinder, Mesh } kind = Kind::Box;
  Vec3d min{0, 0, 0}, max{0, 0, 0};  ///< box (local frame)
  Vec3d center{0, 0, 0};             ///< sphere, cylinder (center of the axis segment)
  double radius = 0.0;               ///< sphere, cylinder
  double height = 0.0;               ///< cylinder, along `axis`
  Vec3d axis{0, 1, 0};               ///< cylinder axis (unit)
  Vec3d point{0, 0, 0};              ///< plane: a point on it
  Vec3d normal{0, 1, 0};             ///< plane: outward normal (unit)
  std::string mesh_path;             ///< mesh: resolved file path
  /// mesh: where `path` was given, for messages, as "file:line: key" (UserError's prefix),
  /// e.g. "shot.yaml:14: colliders[0].shape.path"; "--set K=V: key" for an override.
  std::string mesh_where;
  /// where the shape was given ("file:line: key"), for messages; may be empty
  std::string where;
  double mesh_scale = 1.0;        ///< mesh: uniform scale applied on load
  Vec3d mesh_translate{0, 0, 0};  ///< mesh: translation applied on load
  /// mesh: signed distance (negative inside), built by io/ from the mesh file.
  std::shared_ptr<const SdfGrid> sdf;
};

/// A particle source.
struct SourceDesc {
  std::string name;
  int material = 0;  ///< index into Scene::materials
  ShapeDesc shape;
  double particles_per_cell = 8;
  Vec3d velocity{0, 0, 0};  ///< initial velocity [m/s]
  unsigned seed = 1;        ///< jitter seed (sampling is deterministic)
  bool emit = false;        ///< continuous emission instead of one fill at the start
  int emit_start = 1;       ///< first frame of emission (inclusive)
  int emit_end = 1;         ///< last frame of emission (inclusive)
};

/// One keyframe of a collider's rigid motion (applied about the origin: x' = R s x + T).
struct Keyframe {
  double time = 0.0;          ///< [s]
  Vec3d translate{0, 0, 0};   ///< [m]
  Vec3d rotate_deg{0, 0, 0};  ///< XYZ Euler angles [degrees], R = Rz Ry Rx
};

enum class BoundaryKind { Sticky, Slip, Separate };

/// A collider: a shape, optionally animated, with a boundary condition.
struct ColliderDesc {
  std::string name;
  ShapeDesc shape;
  BoundaryKind boundary = BoundaryKind::Separate;
  double friction = 0.0;            ///< Coulomb coefficient (slip, separate)
  std::vector<Keyframe> keyframes;  ///< empty = static; linear/slerp between keys
};

/// A Kirchhoff-Love shell material (plane-stress Hencky laminate, METHOD.md).
struct ShellMaterialDesc {
  std::string name;
  double youngs_modulus = 1e6;  ///< E [Pa]
  double poisson_ratio = 0.3;   ///< nu, in [0, 0.5)
  double density = 1000.0;      ///< [kg/m^3]
  double thickness = 1e-3;      ///< t [m]
  double yield_stress = 0.0;    ///< von Mises yield [Pa]; 0 = no denting (no plasticity stage)
  /// Principal stretch s_l beyond which the membrane stiffens (kirchhoff_love.h), in
  /// (1, KirchhoffLoveShellT::kMaxStretchLimit]; below it the energy is plain Hencky.
  double stretch_limit = 1.5;
  double damping = 0.0;            ///< mass-proportional damping rate [1/s]
  double stiffness_damping = 0.0;  ///< Rayleigh stiffness-proportional damping [s]
  int quadrature_inplane = 3;      ///< in-plane points per triangle: 1, 3, 6 or 7
  int quadrature_thickness = 3;    ///< Gauss points through the thickness: 1 to 5
  // Contact (issue 4; used when the shell's control points are on the MPM grid).
  double friction = 0.3;                    ///< Coulomb coefficient c_F between shells
  std::optional<double> contact_stiffness;  ///< k_c [Pa]; none: youngs_modulus
  std::optional<double> contact_shear;      ///< gamma [Pa]; none: the contact stiffness
  /// Thickness of the contact layer [m]: contact surfaces lie half of it on each side of
  /// the limit surface. none: the shell's thickness.
  std::optional<double> contact_thickness;
  int contact_samples = 1;           ///< contact particles per triangle: 1, 3, 6 or 7
  std::optional<Vec3d> front_color;  ///< preview colour of the +normal side; none: render's
  std::optional<Vec3d> back_color;   ///< preview colour of the other side; none: render's
};

/// A rigid keyframed motion shared by pins (and colliders).
using Motion = std::vector<Keyframe>;

/// Pinned control points of a shell: chosen by index, by region or by named group.
struct PinDesc {
  std::vector<int> indices;  ///< control point indices
  bool has_box = false;      ///< select points inside [box_min, box_max] (rest pose)
  Vec3d box_min{0, 0, 0}, box_max{0, 0, 0};
  std::string group;                                 ///< a named vertex group of the mesh file
  std::array<bool, 3> components{true, true, true};  ///< which of x, y, z are held
  Motion keyframes;                    ///< empty: fixed at the rest position; else moves rigidly
  std::optional<double> release_time;  ///< the pin lets go after this time [s]; none: never
  /// where the selector was given, for messages, as "file:line: key" (UserError's prefix),
  /// e.g. "shot.yaml:30: shells[0].pins[1].indices" (or .box / .group); may be empty
  std::string where;
};

/// A point load on one control point [N].
struct PointLoadDesc {
  int index = 0;
  Vec3d force{0, 0, 0};
  /// where `index` was given, as "file:line: key", e.g. "shot.yaml:31:
  /// shells[0].point_loads[0].index"; may be empty
  std::string where;
};

/// A shell object: control mesh from a file or made procedurally.
struct ShellDesc {
  std::string name;
  int material = 0;  ///< index into Scene::shell_materials
  enum class Kind { Mesh, Sheet, Cylinder, Sphere } kind = Kind::Sheet;
  // mesh
  std::string mesh_path;
  std::string mesh_where;                 ///< "file:line: key" for messages
  std::shared_ptr<const ShellMesh> mesh;  ///< filled by io/ (load_scene_assets) for Kind::Mesh
  // sheet: a rectangle in the local XZ plane (normal +Y), size along X and Z
  std::array<double, 2> size{1.0, 1.0};
  std::array<int, 2> resolution{10, 10};  ///< quads along X and Z (two triangles each)
  // cylinder patch: axis along local Y, angle in degrees around it (360 = closed tube)
  double radius = 0.5;
  double height = 1.0;
  double angle_deg = 360.0;
  // sphere: icosahedron subdivided `subdivisions` times
  int subdivisions = 2;
  // placement (applied to the rest mesh): x' = R(rotate) * (scale * x) + translate
  double scale = 1.0;
  Vec3d rotate_deg{0, 0, 0};
  Vec3d translate{0, 0, 0};
  /// Where `translate` was given (or the shell, when it was not), as "file:line: key", for
  /// messages about the shell's placement.
  std::string placement_where;
  Vec3d velocity{0, 0, 0};  ///< initial velocity [m/s]
  std::vector<PinDesc> pins;
  double pressure = 0.0;  ///< surface load along the normal [Pa] (positive pushes along +normal)
  std::vector<PointLoadDesc> point_loads;
  int output_refine = 0;  ///< limit-surface refinement levels of the written mesh (0..4)
  /// Frictional contact on the MPM grid: Auto = on when the scene has a collider, bulk
  /// material or another shell; On also gives self-contact of a lone shell.
  enum class Contact { Auto, On, Off } contact = Contact::Auto;
  bool write_mesh = true;
};

/// Pre-roll: settle shells to static equilibrium before frame 1.
struct PrerollSettings {
  bool enabled = false;
  /// Static: minimise the potential energy in double precision (ShellObject::settle);
  /// Dynamic: damped dynamic relaxation (explicit steps with kinetic damping).
  enum class Method { Static, Dynamic } method = Method::Static;
  double tolerance = 1e-4;  ///< stop when max |residual force| / max |gravity force| < tolerance
  int max_steps = 200000;   ///< give up (error) after this many steps (static: iterations)
};

/// The file format of the shell meshes written per frame.
enum class MeshFormat { Ply, Obj, Glb };

/// The up axis of the caches a run writes (output.up_axis). The simulation is always
/// Y-up; Z writes every cache rotated by +90 degrees about X, (x, y, z) -> (x, -z, y)
/// (sim/scene/output_axes.h), except glTF meshes, which glTF 2.0 defines as Y-up.
enum class UpAxis { Y, Z };

/// What to write.
struct OutputSettings {
  std::string directory = "out";
  std::string density_pattern = "density.####.vdb";  ///< '#' run = zero-padded frame
  std::string particles_pattern = "particles.####.ply";
  std::string stats_file = "stats.json";
  bool density = true;  ///< write the density fog volume per frame
  /// Also write a vec3 `vel` grid and, on PLY and GLB shell meshes, per-vertex velocities.
  bool velocity = false;
  bool half_float = false;   ///< store grids as 16-bit floats
  double voxel_size = 0.0;   ///< 0 = the grid spacing dx
  bool particles = false;    ///< particle cache (positions, velocities) per frame
  int checkpoint_every = 0;  ///< frames between checkpoints; 0 = none
  /// Per shell; {name} = the shell's name. The reader defaults the extension to
  /// shell_format (".glb" for glb) and refuses a pattern that names another format.
  std::string shell_pattern = "{name}.####.ply";
  MeshFormat shell_format = MeshFormat::Ply;  ///< ply (binary) | obj | glb
  UpAxis up_axis = UpAxis::Y;                 ///< axes of the caches (not of the simulation)
};

/// A preview camera (render.cameras[]): looks from `position` at `target`.
struct RenderCamera {
  std::string name;
  Vec3d position{0, 1, 3};  ///< eye [m]
  Vec3d target{0, 0, 0};    ///< look-at point [m]
  Vec3d up{0, 1, 0};        ///< up hint (unit); need not be orthogonal to the view
  double fov_deg = 40.0;    ///< vertical field of view [degrees]
};

/// How previews are drawn: OpenGL rasterisation (OSMesa) or ray tracing (Embree).
enum class RendererKind { Raster, Raytrace };
/// How a preview draws the bulk material: Auto picks from the renderer and the outputs.
enum class BulkDraw { Auto, Volume, Surface, Particles, None };

/// Preview rendering (render/, `shellmpm render`, `run --preview`). Colours are linear RGB
/// in [0, 1]. Nothing here changes the simulation.
struct RenderSettings {
  bool preview = false;  ///< render each frame while `run` writes it
  RendererKind renderer = RendererKind::Raster;
  int width = 960, height = 540;  ///< image size [pixels]
  std::string camera;             ///< name in `cameras` or "auto"; empty: first, else auto
  std::vector<RenderCamera> cameras;
  int samples = 4;     ///< ray traced: samples per pixel
  int ao_samples = 2;  ///< ray traced: ambient-occlusion rays per sample
  BulkDraw bulk = BulkDraw::Auto;
  double volume_extinction = 250.0;       ///< extinction of density 1 [1/m]
  double iso_value = 0.5;                 ///< density of the bulk surface
  std::optional<double> particle_radius;  ///< [m]; none: half the particle spacing
  bool ground = true;                     ///< draw a ground plane
  std::optional<Vec3d> key_light;         ///< direction towards the key light; none: camera rig
  Vec3d shell_front{0.80, 0.30, 0.20};    ///< default shell front (+normal side) colour
  Vec3d shell_back{0.20, 0.42, 0.80};     ///< default shell back colour
  Vec3d collider_color{0.45, 0.45, 0.48};
  Vec3d ground_color{0.5, 0.5, 0.48};
  std::string pattern = "preview.####.png";
  bool contact_sheet = true;  ///< contact_sheet.png per run
  bool movie = true;          ///< preview.mp4 when ffmpeg is installed
};

/// A whole shot.
struct Scene {
  std::string path;  ///< the scene file, for messages
  ShotSettings shot;
  std::vector<MaterialDesc> materials;
  std::vector<SourceDesc> sources;
  std::vector<ColliderDesc> colliders;
  std::vector<ShellMaterialDesc> shell_materials;
  std::vector<ShellDesc> shells;
  PrerollSettings preroll;
  OutputSettings output;
  RenderSettings render;
};

}  // namespace shellmpm
