// The embra engine: a world of particles, bodies, constraint groups, pins and colliders, stepped
// with XPBD (Macklin et al. 2016) in substeps (Macklin et al. 2019).
//
// Model and state are kept apart: topology, rest values and compliances live in the constraint
// arrays and bodies; positions, velocities and Lagrange multipliers are the state. Every mutating
// call validates all of its input first and throws embra::Error before touching anything, so a
// refused call leaves the world exactly as it was.
#pragma once

#include "embra/core/constraint_math.hpp"
#include "embra/core/curves.hpp"
#include "embra/core/fields.hpp"
#include "embra/core/kinds.hpp"
#include "embra/core/loads.hpp"
#include "embra/core/shape_match.hpp"

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace embra {

struct ColliderGeometry;  // collision/collider_shapes.hpp

/// Error categories; the C ABI maps them one to one onto its status codes.
enum class ErrorCode : int32_t {
  invalid_argument = 1,
  stale_id = 2,
  buffer_too_small = 3,
  numerical = 4,
  internal = 5,
  cancelled = 6,
};

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const { return code_; }

 private:
  ErrorCode code_;
};

/// A value id: slot index plus generation, so a destroyed object's id is refused, never reused.
struct Id {
  uint32_t index = 0;
  uint32_t generation = 0;  // 0 is never a live generation: a zeroed Id is "none"
  bool is_null() const { return generation == 0; }
  friend bool operator==(const Id&, const Id&) = default;
};

/// m/s: the slip speed over which friction falls from its static to its dynamic coefficient (to
/// 1/e of the difference at this speed; Stribeck's curve without its viscous rise). Contacts at rest
/// hold with the static coefficient, contacts sliding faster than a few times this speed with the
/// dynamic one, and the change between them is continuous.
constexpr double kFrictionStribeckSpeed = 0.01;

struct Material {
  double mass = 0.0;                // kg for the whole body; used when > 0
  double density = 1.0;             // kg per unit of the body's measure (length, area or volume) otherwise
  double stretch_compliance = 0.0;  // m/N (0 = inextensible)
  double shear_compliance = 0.0;    // rad/(N m)
  double bend_compliance = 1.0;     // rad/(N m)
  double volume_compliance = 0.0;   // m^3/N
  double damping = 0.0;             // 1/s, velocity decay rate
  double thickness = 0.0;           // m, shell thickness: particles keep half of it off colliders
  double friction_static = 0.5;     // against colliders (geometric mean with the collider's)
  double friction_dynamic = 0.3;    // reached as the slip speed passes kFrictionStribeckSpeed
};

enum GenerateFlags : uint32_t {
  generate_stretch = 1u << 0,
  generate_shear = 1u << 1,
  generate_bend = 1u << 2,
  generate_volume = 1u << 3,
};

struct BodyDesc {
  std::span<const double> positions;   // 3 per vertex
  std::span<const double> masses;      // optional, 1 per vertex (kg; 0 = immovable)
  std::span<const double> uvs;         // optional, 2 per vertex: material u/v for rest-scale per u/v
  std::span<const int32_t> edges;      // 2 per edge, body-local vertex indices
  std::span<const int32_t> triangles;  // 3 per triangle
  std::span<const int32_t> tets;       // 4 per tetrahedron
  Material material;
  uint32_t generate = generate_stretch | generate_bend | generate_volume;
  Id stretch_group, shear_group, bend_group, volume_group;  // null = the default group
};

struct ConstraintDesc {
  Kind kind = Kind::distance;
  Id group;                            // null = the default group
  std::span<const int32_t> particles;  // arity(kind) per constraint, world particle indices
  std::span<const double> rest;        // one per constraint; empty = measured from current positions
  std::span<const double> compliance;  // one per constraint; empty = `uniform_compliance` for all
  double uniform_compliance = 0.0;
};

struct GroupDesc {
  int32_t order = 0;   // groups are projected in increasing order (ties: creation order)
  int32_t weight = 1;  // projections of the group per solver iteration (>= 1)
  std::string name;
  bool enabled = true;  // false: kept, but not projected, measured or diagnosed (World::set_group_enabled)
};

/// One constraint as a group holds it (World::constraint).
struct ConstraintInfo {
  Kind kind = Kind::distance;
  ParticleSlots particles = no_particles();  // -1 past the kind's arity
  double rest = 0.0;                         // in the kind's unit, before any body's rest scale
  double compliance = 0.0;
  int32_t body = -1;     // the body that generated it (it follows the body's material), or -1: added
  double yield = 0.0;    // World::set_constraint_plasticity; 0 = elastic
  double rupture = 0.0;  // 0 = unbreakable
};

/// A constraint that broke (World::set_constraint_plasticity): named as it was named when it
/// broke, in the frame `frame` (the step that produced it), with the strain it broke at.
struct BrokenConstraint {
  Id group;
  Kind kind = Kind::distance;
  int64_t index = 0;
  ParticleSlots particles = no_particles();
  int64_t frame = 0;
  double strain = 0.0;
};

/// What a pin holds (the numbering is part of the C ABI: embra_pin_support). A plane or line
/// support lets its particle slide, frictionless, on the plane through the target normal to `axis`
/// or on the line through it along `axis`. A polyline support holds its particle on the closest
/// point of a polyline (open, or closed back to its first point) whose points are offsets from the
/// target: moving the target moves the curve. A per-axis anchor (`axes`, Kangaroo's AnchorXYZ, a
/// roller) holds the world coordinates whose `axis` component is 1 at the target's and leaves those
/// whose component is 0 free: {0, 0, 1} holds z and lets x and y slide. A mesh support (Kangaroo's
/// OnMesh) holds its particle on the closest point of a triangle mesh whose vertices are offsets
/// from the target: moving the target moves the mesh, as a host moves a collider.
enum class PinSupport : int32_t { point = 0, plane = 1, line = 2, polyline = 3, axes = 4, mesh = 5 };
constexpr int kPinSupportCount = 6;

struct PinDesc {
  int32_t particle = 0;
  Vec3 target = Vec3::Zero();
  double compliance = 0.0;  // 0 = hard (the particle follows the target exactly), else m/N
  Id group;                 // group of a soft pin or a support; null = the default group
  PinSupport support = PinSupport::point;
  Vec3 axis = Vec3(0.0, 0.0, 1.0);  // plane: its normal; line: its direction (any length > 0);
                                    // axes: 1 per held world coordinate, 0 per free one (not all 0)
  // polyline: its points (m, offsets from the target), at least 2 (closed: 3), no two consecutive
  // ones equal (nor the last and the first, closed), at most limits::kMaxParticles
  std::vector<Vec3> curve{};
  bool closed = false;
  // mesh: its vertices in `curve` (m, offsets from the target; 3 to limits::kMaxParticles) and its
  // triangles here (1 to limits::kMaxConstraints; indices into `curve`, each of nonzero area)
  std::vector<std::array<int32_t, 3>> triangles{};
};

/// The numbering is part of the C ABI (embra_collider_shape).
enum class ColliderShape : int32_t { plane = 0, sphere = 1, box = 2, capsule = 3, convex = 4, mesh = 5 };
constexpr int kColliderShapeCount = 6;

/// q scaled to unit length, or q itself when it is unit already to within rounding (16 ulp of its
/// squared norm): so normalizing twice gives the bits of normalizing once, and a rotation saved to
/// a scene loads back to the same bits.
inline Eigen::Quaterniond unit_rotation(const Eigen::Quaterniond& q) {
  return std::abs(q.squaredNorm() - 1.0) <= 16.0 * std::numeric_limits<double>::epsilon() ? q : q.normalized();
}

struct ColliderDesc {
  ColliderShape shape = ColliderShape::plane;
  Vec3 position = Vec3::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // plane normal = local +z
  double radius = 1.0;                                           // sphere and capsule radius (m)
  Vec3 half_extents = Vec3(0.5, 0.5, 0.5);                       // box: half size along local x, y, z (m)
  double half_length = 0.5;        // capsule: half the length of its axis segment, along local z (m)
  std::vector<double> vertices;    // convex: the points (3 each, local, m); mesh: the vertices
  std::vector<int32_t> triangles;  // mesh: 3 vertex indices per triangle (outward counter-clockwise
                                   // when closed; a closed mesh wound inward is turned)
  double thickness = 0.0;          // extra clearance kept by particles (m)
  double friction_static = 0.5;
  double friction_dynamic = 0.3;
};

struct Settings {
  double dt = 1.0 / 60.0;                // s per frame (one call to step)
  int32_t substeps = 16;                 // chosen on the 128x128 cloth benchmark (bench/README.md)
  int32_t iterations = 1;                // passes over the ordered groups per substep
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);  // m/s^2
  double damping = 0.0;                  // 1/s, applied to every particle
  double settle_speed = 1e-3;            // m/s: settled when no particle moves faster
  // Realignment passes per substep (0 = textbook XPBD). XPBD projects each constraint along its
  // gradient where it stands at that moment and drops the term g = M (x - x~) - grad C(x)^T lambda
  // (Macklin et al. 2016, eq. 11), so a converged substep is the true implicit step only to O(h^2):
  // a settled structure sits off its static equilibrium by O(h^2 g). A pass resets
  // x = x~ + M^-1 grad C(x)^T lambda with the current gradients and runs the iterations again,
  // which drives g to zero: the settled state becomes the equilibrium to rounding. Costs one gradient
  // sweep and `iterations` more projection passes per substep.
  int32_t realign_passes = 0;
  int32_t chebyshev_rho_milli = 0;  // embra_solver_def.chebyshev_rho_milli: [0, 990], 0 off
  int32_t tethers = 2;              // automatic long-range attachments per particle (0 = none)
  // 1 (default): distance constraints laid end to end in straight runs over the bodies' rest shapes
  // (a cloth grid's rows, columns and diagonals) are projected a run at a time in the first iteration
  // of each substep (not with realignment passes), each run as one linearised XPBD system solved
  // exactly (tridiagonal), so a correction travels the whole run in one pass; 0: one constraint at a
  // time (embra_solver_def.chain_solve, which says why only the first iteration).
  int32_t chain_solve = 1;
  Id contact_group;  // set by the world: the group that holds collider contacts
  // 1: cloth and shells (bodies with triangles) collide with themselves and each other, point against
  // triangle and edge against edge, kept their thickness apart (self_collision.hpp); 0 (default): off.
  int32_t self_collision = 0;
  // Threads the solver uses, the caller's included: 1 (default) none besides it; 0 every core of the
  // machine; at most limits::kMaxThreads. Each colour's constraints and chains are split over them;
  // the result is the same bits at any count.
  int32_t threads = 1;
  // 1: each substep's implicit problem over every constraint and soft pin of the enabled groups is
  // first solved as one system, by Newton's method with a sparse factorisation
  // (solver/global_solve.cpp), then the iterations run on from it; 0 (default): the iterations alone;
  // kGlobalSolveAuto (2): as 1 in a world without colliders or self-collision while the system has at
  // most kGlobalSolveAutoLimit unknowns.
  int32_t global_solve = 0;
};

/// Settings::global_solve's automatic mode, and its limit: 3 unknowns per movable particle plus one
/// per constraint row (a weld and a soft pin have 3). A direct factorisation's cost grows faster than
/// the size (embra_solver_def.global_solve has the figures), the iterations' with it.
constexpr int32_t kGlobalSolveAuto = 2;
constexpr int64_t kGlobalSolveAutoLimit = 20000;

struct GroupReport {
  int64_t count = 0;
  double residual_max = 0.0;
  double residual_rms = 0.0;
};

/// The residuals of one kind of constraint over the world, in the kind's own unit (KindInfo::unit;
/// pins and contacts: m).
struct KindResidual {
  int64_t count = 0;
  double max = 0.0;
  double rms = 0.0;
};
/// StepReport::by_kind: the constraint kinds in table order, then the pins (soft and hard), then the
/// contacts (penetration of particles into colliders and of panel faces into spheres).
constexpr int kResidualPins = kKindCount;
constexpr int kResidualContacts = kKindCount + 1;
constexpr int kResidualKinds = kKindCount + 2;

/// One constraint (or soft pin) of the last step, as the diagnostics see it (World::worst_constraints).
struct ConstraintResidual {
  int32_t kind = 0;  // Kind, or kResidualPins for a soft pin
  Id group;
  int32_t index = -1;  // in the group's constraints of that kind (ConstraintArray order); -1 for a pin
  Id pin;              // the soft pin
  ParticleSlots particles = no_particles();  // -1 past the kind's arity
  double residual = 0.0;                     // |C + alpha~ lambda| in the kind's unit
  double violation = 0.0;                    // |C|: how far from its rest, in the kind's unit
  double force = 0.0;                        // |lambda| / h^2 of the last substep: N (rad kinds: N m; volume: N/m^2)
};

/// Two groups pulling the same particles opposite ways (World::group_conflicts).
struct GroupConflict {
  Id a, b;                // a before b in the projection order
  double force = 0.0;     // N: over their shared particles, the smaller of the two groups' forces on
                          // each times how far they point against each other (-cos, where negative)
  int64_t particles = 0;  // particles where their forces point more than 120 degrees apart
};

/// The force a pin exerts on its particle after the last step (World::reactions).
struct Reaction {
  Id pin;
  int32_t particle = 0;
  Vec3 force = Vec3::Zero();  // N
};

/// The force a collider exerts on the world after the last step (World::collider_reactions): the
/// sum over its contacts of the last substep, normal push and friction.
struct ColliderReaction {
  Id collider;
  Vec3 force = Vec3::Zero();   // N, on the particles
  Vec3 moment = Vec3::Zero();  // N m, of those forces about the collider's position
  int64_t contacts = 0;        // contacts that pushed (lambda > 0) in the last substep
};

struct StepReport {
  int64_t frame = 0;            // frames stepped since creation
  double time = 0.0;            // simulated seconds
  double kinetic_energy = 0.0;  // J
  double max_speed = 0.0;       // m/s
  double residual_max = 0.0;    // over all constraints, in each constraint's own unit (mixed: by_kind
  double residual_rms = 0.0;    // says which unit)
  std::array<KindResidual, kResidualKinds> by_kind{};
  int64_t constraint_count = 0;
  int64_t contact_count = 0;
  bool settled = false;
};

class World;

/// What a caller hands World::step beyond the world itself.
struct StepControl {
  /// Run once at the start of the frame, after the restore point is taken: changes it makes (a
  /// scene's actions: pin targets, collider poses, gravity, rest scales) are undone with the frame
  /// when it fails.
  std::function<void(World&)> before_frame;
  /// Checked between iterations: when set, the frame stops, the world is restored and step throws
  /// Error(cancelled). Another thread may set it while the step runs.
  const std::atomic<bool>* cancel = nullptr;
};

struct Warning {
  int64_t frame = -1;     // frame of the last numerical failure, -1 if none
  int32_t particle = -1;  // first particle found non-finite
  std::string message;
};

struct BodyInfo {
  int32_t first_particle = 0;
  int32_t particle_count = 0;
  Material material;
  double rest_scale = 1.0, rest_scale_u = 1.0, rest_scale_v = 1.0;
  std::vector<int32_t> triangles;  // world particle indices
  std::vector<int32_t> tets;
  bool has_uv = false;
  std::vector<int32_t> edges;        // unique edges (2 per edge, world particle indices, lower first)
  std::vector<Vec3> rest_positions;  // the vertices as given at creation (the body's rest shape)
  Id stretch_group;                  // the group holding the generated stretch constraints
  bool generated_stretch = false;    // whether stretch constraints were generated
  // The rest of the creation description, so the body can be saved and built again exactly.
  std::vector<double> masses;  // kg per vertex, as computed at creation
  std::vector<double> uvs;     // 2 per vertex, empty without uvs
  uint32_t generate = 0;       // GenerateFlags
  Id shear_group, bend_group, volume_group;
};

/// A plain array of constraints of one kind, in one group: operands, rest and compliance (model)
/// and accumulated multipliers (state). `rest_u/rest_v` split a distance's rest length into its
/// material u and v parts so a body's per-direction rest-length scale applies; `body` is the body
/// whose scale applies (-1: none).
struct ConstraintArray {
  std::vector<int32_t> ids;  // arity per constraint
  std::vector<double> rest;
  std::vector<double> rest_u, rest_v;
  std::vector<int32_t> body;
  std::vector<double> compliance;
  std::vector<double> rest_now;  // rest after scaling, refreshed when scales change
  std::vector<double> lambda;    // for welds: 3 per constraint
  // Plasticity and rupture of an added distance or dihedral (World::set_constraint_plasticity):
  // the strain past which its rest follows it, and past which it breaks; 0 = never.
  std::vector<double> yield, rupture;
  size_t generated = 0;  // the first `generated` entries come from bodies, in body order; added
                         // constraints follow in the order added (so a saved world loads the same)
  size_t size() const { return rest.size(); }
};

/// The solver's working copy of a constraint array, ordered by colour: constraints of one colour
/// share no particle, so a colour can be projected in any order, or in parallel, with the same
/// result. Built from a group's ConstraintArray (and from the automatic tethers) when constraints
/// or pins change; `source` maps each entry back to its ConstraintArray slot.
struct SolverArray {
  std::vector<int32_t> ids;     // arity per constraint
  std::vector<int32_t> source;  // slot in the group's ConstraintArray; -1 for an automatic tether
  std::vector<double> rest;     // current rest value (rest scales applied)
  std::vector<double> compliance;
  std::vector<double> lambda;         // accumulated multiplier (3 per weld)
  std::vector<double> base_rest;      // automatic tethers: rest before the body's rest scale
  std::vector<int32_t> body;          // automatic tethers: the body whose rest scale applies
  std::vector<int32_t> colour_start;  // colour c is [colour_start[c], colour_start[c + 1])
  bool shared_tail = false;           // the last colour's constraints may share particles (project in order)
  // Distance arrays under Settings::chain_solve: the constraints as chains, straight runs end to end.
  // Chain c is the constraints chain_edge[chain_start[c] .. chain_start[c + 1]) in order, joining the
  // particles chain_part[chain_start[c] + c .. chain_start[c + 1] + c] (one more than constraints);
  // no particle appears twice in a chain. Every constraint is in exactly one chain, or, where each
  // chain would be a single constraint, there are none (the plain pass projects them the same way).
  std::vector<int32_t> chain_start, chain_edge, chain_part;
  // The chains by colour: colour c is chains [chain_colour_start[c], chain_colour_start[c + 1]), which
  // share no particle (so they can be solved side by side), longest first; the last colour may share
  // particles when chain_shared_tail (solved one chain after another).
  std::vector<int32_t> chain_colour_start;
  bool chain_shared_tail = false;
  // Automatic tethers: the tethers of one particle, together. Run r is the entries
  // run_entry[run_start[r] .. run_start[r + 1]) of this (colour-ordered) array, all pulling the same
  // particle towards immovable anchors; runs share no particle.
  std::vector<int32_t> run_start, run_entry;
  // The runs of exactly two tethers (projected side by side, a block of lanes at a time) and the others.
  std::vector<int32_t> pair_runs, other_runs;
  // The constraints holding a hard-pinned particle (World::find_pinned_slots, for the reactions,
  // which read the last substep of a frame): entry j is constraint pinned[3 j] (this array's
  // order, ascending), its slot pinned[3 j + 1] (the particle's place among its ids) and the pin
  // pinned[3 j + 2] (World::pins index).
  std::vector<int32_t> pinned;
  size_t size() const { return rest.size(); }
  size_t colours() const { return colour_start.empty() ? 0 : colour_start.size() - 1; }
};

/// A self-collision contact (core/src/self_collision.hpp): the hard unilateral constraint
/// normal . sum_k weight[k] x[ids[k]] - thickness >= 0 between a point and a triangle (ids: the point,
/// then the corners; weights 1, -barycentric) or two edges (a0, a1, b0, b1; 1 - s, s, -(1 - t), -t).
struct SelfContact {
  int32_t ids[4];
  double weight[4];
  Vec3 normal;
  double thickness;
  double mu_s, mu_k;
  double lambda;
};

/// Self-collision candidate pairs (core/src/self_collision.hpp), kept while every particle stays
/// inside the region [lo, hi] it had when they were found.
struct SelfCollisionIndex;    // collision/self_collision.cpp
struct SelfCollisionScratch;  // collision/self_collision.cpp
struct SelfCollisionCache {
  std::vector<Vec3> lo, hi;             // per particle
  std::vector<int32_t> point_triangle;  // (particle, triangle) pairs
  std::vector<int32_t> edge_edge;       // (edge, edge) pairs
  // Per pair: a lower bound of its distance less its thickness at the start of the last substep
  // (-inf until it is measured).
  std::vector<double> point_triangle_gap, edge_edge_gap;
  std::vector<int32_t> triangles, edges;          // the primitives they were found for (world indices)
  std::shared_ptr<SelfCollisionIndex> index;      // the regions' boxes and their hierarchy
  std::shared_ptr<SelfCollisionScratch> scratch;  // the detection's working arrays (their storage)
};

struct Contact {
  int32_t particle;
  int32_t collider;
  double lambda;
  // Box, capsule, convex and mesh colliders: a contact found where the particle's path entered the
  // collider within the substep holds the particle on the tangent plane there (local normal n,
  // n . local >= offset), so it leaves on the side it came from; otherwise (swept = false) the
  // closest point of the surface is used, found again at every projection.
  bool swept = false;
  Vec3 normal = Vec3::Zero();
  double offset = 0.0;
  // kg m: the contact's force on the particle in the last substep times h^2 (World::collider_reactions):
  // its push lambda / w along the normal where the solve left the particle (recorded as friction
  // starts), friction's and the push back onto the surface (settle_contacts_on_surface).
  Vec3 force_h2 = Vec3::Zero();
};

/// A face contact (panel meshes against sphere colliders): the point of triangle `ids` (of either
/// layer) closest to the sphere's centre, sum_k b_k x_k with barycentric weights b found again at
/// every projection, kept the sphere's radius plus its thickness from the centre.
/// The push moves each corner together with its partner in the other layer (`partner`, the corner
/// straight across the panel), as one particle of their joint mass: a panel is pushed as a slab
/// instead of its touching face being pushed against the plane offsets that hold it to the other
/// face. Hard and unilateral; lambda is the accumulated push along the normal.
struct FaceContact {
  int32_t ids[3];
  int32_t partner[3];
  int32_t collider;
  double lambda;
  // kg m: the contact's force on the movable corner pairs times h^2, normal push (as the solve left
  // them) and friction (apply_friction; World::collider_reactions).
  Vec3 force_h2 = Vec3::Zero();
};

/// What the force readers (World::constraint_forces, reactions, collider_reactions, and the
/// diagnostics' forces) read of the last step beyond the positions and the model: the multipliers of
/// its last substep and its contacts' forces. A saved scene keeps it (state.forces,
/// docs/scene-format.md) so that a loaded world reads the forces the saved one read before its first
/// step. Stepping never reads it: each substep sets every multiplier to 0 and finds its contacts
/// afresh before projecting.
struct StaticsState {
  struct Multipliers {
    Id group;
    Kind kind = Kind::distance;
    std::vector<double> lambda;  // multipliers(kind) per constraint, in ConstraintArray order
  };
  struct Tethers {
    Id group;
    std::vector<double> lambda;  // one per automatic tether, in the solver's (colour) order
  };
  struct PinMultiplier {
    Id pin;
    Vec3 lambda = Vec3::Zero();
  };
  std::vector<Multipliers> constraints;    // a (group, kind) not listed: all 0
  std::vector<Tethers> tethers;            // a group not listed: all 0
  std::vector<PinMultiplier> pins;         // a pin not listed: 0 (a hard pin: its impulse, Pin::lambda)
  std::vector<Contact> contacts;           // particle, collider (slot) and force_h2 are what is read
  std::vector<FaceContact> face_contacts;  // ids, collider (slot) and force_h2 are what is read
  bool empty() const {
    return constraints.empty() && tethers.empty() && pins.empty() && contacts.empty() && face_contacts.empty();
  }
};

/// A group's distance, planarity and plane-offset rows as islands (World::rebuild_solver), in a
/// group that projects no other kind between those three; each island of at most kSlots particles
/// and kSteps rows, its particles held in registers while its rows are projected in turn, islands
/// of the same shape side by side in lanes. Two layouts:
/// - welded panels: the rows joined by shared particles (a panel each: the welds, which join them,
///   are projected before), no island sharing a particle with another, all in one colour. An
///   island's rows go in the passes' order (distances, then planarity, then plane offsets, each in
///   colour order), so every particle sees the three passes' projections in their order: the bits
///   are the passes', loaded and stored once per island instead of once per row, and the passes'
///   colours are one parallel loop.
/// - panels sharing their corners: every row joins every panel, so each row goes to one panel that
///   holds all its particles, and the panels are coloured so that none of a colour shares a
///   particle (four colours on a grid, against the passes' 32). A panel's rows go by kind, in the
///   order they were added: a Gauss-Seidel sweep panel by panel, not the passes' order.
/// tests/scenes/kernels_same_bits.sh checks the bits: EMBRA_ISLANDS=rows projects the islands' rows
/// in the same order one at a time with the pass kernels (either layout), EMBRA_ISLANDS=off the
/// passes instead of islands (the welded layout's bits; the shared layout's differ). Islands in
/// single precision (Shape::single) have bits of their own, the same at every lane width.
struct IslandPlan {
  static constexpr int kSlots = 8;     // particles of an island, at most
  static constexpr int kSteps = 32;    // rows of an island, at most
  static constexpr int kRowKinds = 3;  // the kinds of its rows: distance, planarity, plane offset
  static constexpr Kind kRowKind[kRowKinds] = {Kind::distance, Kind::planarity, Kind::plane_offset};
  struct Shape {  // islands with the same rows on the same local particles
    int32_t slots = 0, steps = 0;
    std::vector<int8_t> kind;       // per step: 0 distance, 1 planarity, 2 plane offset
    std::vector<int8_t> slot;       // per step: 4 local particles (a distance uses 2)
    std::vector<int32_t> particle;  // per island: its `slots` particles
    std::vector<int32_t> row;       // per island: its `steps` rows (indices into that kind's array)
    /// Projected in single precision (a panel mesh's PanelPrecision::single): positions relative to
    /// each island's first particle, the moves summed from zero and added to the double positions.
    bool single = false;
    /// Per island: its rows' multipliers while a pass projects the islands (IslandEnds: taken from
    /// the arrays at its first projection, given back at its last where something reads them);
    /// scratch the kernels write.
    mutable std::vector<double> lambda;
    /// In single precision, `lambda` in floats instead, with the rows' rest values and compliances
    /// over h^2 (copied from the arrays once a frame, island_operands): item by item (Item), an
    /// item's rows step by step, its islands side by side (row `step` of island first + k at
    /// first * steps + step * count + k), so that a block of lanes loads each with one instruction.
    mutable std::vector<float> lambda_single, rest_single, alpha_single;
    size_t islands() const { return slots == 0 ? 0 : particle.size() / static_cast<size_t>(slots); }
  };
  struct Item {  // up to kItemIslands consecutive islands of one shape
    int32_t shape = 0, first = 0, count = 0;
    // Where its first island lies among its colour's islands, from 0 to 1: the panels' order, so
    // the same stretch of the mesh in every colour (the threads' parts are cut there).
    double place = 0.0;
  };
  static constexpr int kItemIslands = 8;  // two blocks of 4 lanes (the kernels run two side by side)
  std::vector<Shape> shapes;
  std::vector<Item> items;
  /// Colour c: items [colour_start[c], colour_start[c + 1]), whose islands share no particle; the
  /// colours in turn (one colour when no island shares a particle with another).
  std::vector<int32_t> colour_start;
  /// Where each colour's items are cut into the threads' parts: part p takes the items placed in
  /// [cut[p], cut[p + 1]), cut[0] = 0 and cut[parts] = 1 (parts + 1 a colour). It starts at
  /// p / parts and moves a quarter of the way to the places where the parts would have taken equal
  /// time: a thread's stretch can cost more than its share of the items (the cache lines it shares
  /// with another core, the particles the caller's serial stages touched). islands_pass keeps one
  /// cut for every colour (Flow), moved every few calls from the parts' times over all colours;
  /// islands_colour, where the colours go one at a time (one colour, or too few items to split
  /// every colour), moves each colour's own after it. Which thread projects an item changes no
  /// bit: this balances time only.
  std::vector<double> cut;
  /// How islands_pass runs the colours of one iteration on its threads' parts without a hand-over
  /// between colours (ThreadPool::run_lines): per colour c and part p, the first item of the part
  /// (`start`, parts + 1 a colour, from `cut`), and how many of the part's first and last items
  /// (`lead`, `trail`) hold a particle that an item of another part also holds: its border. A part
  /// projects its border first and the rest after; another part's border of the next colour waits
  /// only for that, its own items for nothing. Found again when the cut has moved an item to another
  /// part, looked at every few calls.
  struct Flow {
    std::vector<int32_t> start, lead, trail;
    std::vector<uint64_t> parts_of;  // scratch: per particle, a bit for each part holding it
    std::vector<double> seconds;     // per part (8 apart): the time its items took
    int calls = 0;                   // calls since `start` last followed the cut
  };
  Flow flow;
  /// Per item: 1 when one of its rows holds a hard-pinned particle (World::find_pinned_slots, with
  /// the arrays' `pinned` lists): the tracked substep projects those items row by row.
  std::vector<uint8_t> pinned_items;
  bool active() const { return !items.empty(); }
  /// Calls f(particle) for each particle slot of each island of item `i`, in their order.
  template <class F>
  void each_particle(size_t i, F&& f) const {
    const Item& it = items[i];
    const Shape& shape = shapes[static_cast<size_t>(it.shape)];
    const size_t slots = static_cast<size_t>(shape.slots);
    for (size_t at = static_cast<size_t>(it.first) * slots; at < static_cast<size_t>(it.first + it.count) * slots; ++at)
      f(static_cast<size_t>(shape.particle[at]));
  }
};

struct Group {
  GroupDesc desc;
  uint32_t generation = 0;
  bool alive = false;
  int64_t serial = 0;  // creation order, to break ties in `order`
  ConstraintArray arrays[kKindCount];
  SolverArray solve[kKindCount];   // the arrays in colour order, as the solver projects them
  SolverArray tethers;             // automatic long-range attachments (Settings::tethers)
  IslandPlan islands;              // the distance, planarity and plane-offset rows, when they form islands
  std::vector<int32_t> soft_pins;  // indices into World::pins_
  std::vector<ShapeMatch> shapes;  // World::add_shape_match, projected after the constraint kinds
  std::vector<Contact> contacts;   // only in the contact group
  GroupReport report;
};

struct Pin {
  int32_t particle = 0;
  Vec3 target = Vec3::Zero();
  Vec3 target_prev = Vec3::Zero();  // hard pin: its particle's position at the start of the frame
  double compliance = 0.0;
  Id group;
  PinSupport support = PinSupport::point;
  Vec3 axis = Vec3(0.0, 0.0, 1.0);  // unit (plane, line); axes: 1 held, 0 free, per coordinate
  std::vector<Vec3> curve;          // polyline: its points; mesh: its vertices (offsets from the target)
  bool closed = false;
  std::vector<std::array<int32_t, 3>> triangles;  // mesh: its triangles
  // A projected pin: its accumulated multiplier (kg m). A hard pin: the impulse times h its particle
  // took from the constraints in the last substep, sum grad C dlambda over every projection that
  // held it (kg m; its force is lambda / h^2).
  Vec3 lambda = Vec3::Zero();
  uint32_t generation = 0;
  bool alive = false;
  /// A hard point pin: its particle is kinematic (inverse mass 0), carried to the target. Every
  /// other pin (soft, or a support of any compliance) is projected in its group.
  bool kinematic() const { return compliance == 0.0 && support == PinSupport::point; }
  /// The part of d (the particle's offset from the target) the pin holds: all of it for a point,
  /// its part along the normal for a plane, its part across the line for a line.
  /// For a polyline (a mesh): d less the closest point of the curve (the mesh), the offset from it. For axes: its held
  /// coordinates (the free ones 0, exactly).
  Vec3 held(const Vec3& d) const {
    switch (support) {
      case PinSupport::axes:
        return Vec3(axis.x() != 0.0 ? d.x() : 0.0, axis.y() != 0.0 ? d.y() : 0.0, axis.z() != 0.0 ? d.z() : 0.0);
      case PinSupport::plane:
        return axis.dot(d) * axis;
      case PinSupport::line:
        return d - axis.dot(d) * axis;
      case PinSupport::polyline:
        return d - closest_point_on_polyline(curve, closed, d).point;
      case PinSupport::mesh:
        return d - closest_point_on_mesh(curve, triangles, d).point;
      case PinSupport::point:
        break;
    }
    return d;
  }
};

/// A collider's pose moves along a straight path from where it was at the start of the frame to
/// `desc` (the pose the host set) over the frame's substeps.
struct Collider {
  ColliderDesc desc;                   // desc.position/rotation: the pose at the end of the frame
  Vec3 frame_position = Vec3::Zero();  // pose at the start of the frame
  Eigen::Quaterniond frame_rotation = Eigen::Quaterniond::Identity();
  Vec3 position = Vec3::Zero();  // pose at the end of the current substep
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Vec3 position_prev = Vec3::Zero();  // pose at the start of the current substep
  Eigen::Quaterniond rotation_prev = Eigen::Quaterniond::Identity();
  std::shared_ptr<const ColliderGeometry> geometry;  // box, capsule, convex, mesh: built at creation
  uint32_t generation = 0;
  bool alive = false;
};

/// A long-range attachment: `particle` may be at most `rest` from `anchor` (a tether).
struct Attachment {
  int32_t particle = 0;
  int32_t anchor = 0;
  double rest = 0.0;
};

/// The long-range attachments of a body: each of its particles to its `per_particle` nearest
/// `anchors` (world indices of the body's particles), nearest by path length over the body's rest
/// shape (edges, and straight lines across coplanar triangles). A rest length is the length of a
/// path over the surface, so it is never shorter than the geodesic distance: a tether never holds
/// back a shape the body can take without stretching, and on a flat piece it is the straight-line
/// distance. Deterministic. A straight link is checked by a walk over the triangles it crosses,
/// except on a flat sheet that covers the convex hull of its vertices once (every link lies on it):
/// there the cost is that of a Dijkstra search per anchor. `walk_always`: walk every link even
/// there (the tests compare the two).
std::vector<Attachment> long_range_attachments(const BodyInfo& body, std::span<const int32_t> anchors,
                                               int32_t per_particle, bool walk_always = false);

/// A panel mesh (core/include/embra/core/panels.hpp): a body whose particles are its panels' corners.
/// Welded (`shared` false): 8 per panel in panel order, the top quad's corners 0-3, then the bottom
/// quad's corners 0-3 (the bottom layer, `thickness` below the top on the side opposite the top's
/// normal); corners of different panels on one mesh vertex are welded. Shared: 2 per mesh vertex,
/// the top layer's vertices 0 .. vertex_count - 1, then the bottom layer's in the same order; the
/// panels on a vertex share its two particles. `quads` gives, per panel, the vertex of the top mesh
/// each corner sits on (counter-clockwise seen from the top's normal side).
struct PanelTopology;  // panels.hpp

struct PanelLayout {
  Id body;
  int32_t first_particle = 0;
  int32_t vertex_count = 0;    // vertices of the top mesh
  std::vector<int32_t> quads;  // 4 mesh vertex indices per panel
  double thickness = 0.0;      // model units
  bool shared = false;         // corners shared per mesh vertex (2 particles a vertex), else welded
  bool single = false;         // its rows' islands projected in single precision (PanelPrecision)
  // Derived from the quads by World::set_panel_layout (panel_topology, panels.hpp) for the metrics;
  // null in a layout made by hand, for which the metrics derive it each time.
  std::shared_ptr<const PanelTopology> topology;
  int32_t panel_count() const { return static_cast<int32_t>(quads.size() / 4); }
  int32_t top(int32_t panel, int corner) const {
    return shared ? first_particle + quads[static_cast<size_t>(4 * panel + corner)]
                  : first_particle + 8 * panel + corner;
  }
  int32_t bottom(int32_t panel, int corner) const {
    return shared ? first_particle + vertex_count + quads[static_cast<size_t>(4 * panel + corner)]
                  : first_particle + 8 * panel + 4 + corner;
  }
  /// Particles of the body: 8 a panel welded, 2 a vertex shared.
  int64_t particle_count() const {
    return shared ? 2 * int64_t{vertex_count} : 8 * static_cast<int64_t>(quads.size() / 4);
  }
};

/// The projection kernels this machine runs: "avx2" (4 constraints at a time), "vec2" (2) or
/// "scalar". All give the same bits; the environment variable EMBRA_KERNELS forces one.
const char* solver_kernels();

/// The form-finding preset (embra_form_finding_solver_def, which states what it reaches): the
/// defaults with dt 1/15 s, 1 substep, 1 iteration and velocity damping 6/s; for the shape a
/// structure comes to rest in rather than the motion on the way.
inline Settings form_finding_settings() {
  Settings s;
  s.dt = 1.0 / 15.0;
  s.substeps = 1;
  s.iterations = 1;
  s.damping = 6.0;
  s.global_solve = kGlobalSolveAuto;
  return s;
}

class ThreadPool;
struct GlobalSolve;

/// The world. Not thread-safe: one thread at a time per world; different worlds are independent.
class World {
 public:
  explicit World(const Settings& settings = Settings());
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;

  // --- settings --------------------------------------------------------------------------------
  const Settings& settings() const { return settings_; }
  void set_settings(const Settings& settings);
  void set_gravity(const Vec3& g);

  // --- bodies ----------------------------------------------------------------------------------
  Id create_body(const BodyDesc& desc);
  const BodyInfo& body(Id id) const;
  void set_rest_scale(Id body, double scale, double scale_u, double scale_v);
  size_t body_count() const { return bodies_.size(); }

  // --- groups ----------------------------------------------------------------------------------
  Id create_group(const GroupDesc& desc);
  void destroy_group(Id id);
  void set_group_order(Id id, int32_t order);
  void set_group_weight(Id id, int32_t weight);
  const Group& group(Id id) const;
  Id default_group() const { return default_group_; }
  /// The per-particle passes' parts once the solver is built (find_particle_parts): runs of
  /// particles (begin, end, part), in order; empty where the passes cut the particles into equal
  /// ranges. For tests and diagnostics.
  const std::vector<std::array<int32_t, 3>>& particle_runs() const { return particle_runs_; }
  Id contact_group() const { return settings_.contact_group; }
  size_t group_count() const;

  // --- constraints -----------------------------------------------------------------------------
  /// Adds `particles.size() / arity(kind)` constraints to a group; returns how many were added.
  int64_t add_constraints(const ConstraintDesc& desc);
  /// Adds tether constraints (long-range attachments, see long_range_attachments) from every
  /// particle of `body` to its `per_particle` nearest anchors: the body's particles that are
  /// hard-pinned or immovable now. They go to `group` (null = the default group) as ordinary
  /// constraints; Settings::tethers makes the same attachments automatically and keeps them up to
  /// date as pins come and go. Returns how many were added (0 when the body has no anchor).
  int64_t add_tethers(Id body, Id group, int32_t per_particle);
  int64_t constraint_count() const;

  // --- edits: each changes only what it names; positions, velocities and every other constraint
  // stay as they were. A constraint is named as the diagnostics name it: its group, kind and index
  // in the group's constraints of that kind (ConstraintArray order: those bodies generated first, in
  // body order, then the added ones in the order added). Only added constraints are edited one at
  // a time; those a body generated follow its material (set_material).
  /// How many constraints of `kind` the group holds, and how many of them bodies generated.
  std::pair<int64_t, int64_t> constraint_count(Id group, Kind kind) const;
  ConstraintInfo constraint(Id group, Kind kind, int64_t index) const;
  void set_constraint_compliance(Id group, Kind kind, int64_t index, double compliance);
  /// `rest` in the kind's unit, checked as embra_constraint_add checks it.
  void set_constraint_rest(Id group, Kind kind, int64_t index, double rest);
  /// Moves the constraint to the end of group `to`'s constraints of its kind; returns its index
  /// there. The constraints after it in `group` move down by one.
  int64_t move_constraint(Id group, Kind kind, int64_t index, Id to);
  /// Removes the constraint; the constraints after it in `group` move down by one.
  void remove_constraint(Id group, Kind kind, int64_t index);
  /// Plasticity and rupture of an added distance or dihedral, checked after every step at the
  /// step's end positions. Its strain is (length - rest) / rest for a distance (dimensionless) and
  /// angle - rest (rad, wrapped) for a dihedral. Past `yield` (> 0) the rest follows the constraint
  /// so that the strain is `yield` again (perfect plasticity: a permanent set); past `rupture`
  /// (> 0) the constraint is removed (later ones move down by one) and reported by take_broken.
  /// 0 turns either off; each finite, >= 0 (a distance of rest 0 has no strain: refused).
  void set_constraint_plasticity(Id group, Kind kind, int64_t index, double yield, double rupture);
  /// Shape matching (shape_match.hpp): the points `particles` (at least 3, distinct) pulled each
  /// substep toward the best-fit rigid placement of `rest` (one point per particle, m; empty: the
  /// current positions), with `compliance` (m/N, >= 0; 0 = hard), in `group` (null = the default
  /// group), projected after the group's constraints. Returns its index among the group's shape
  /// matches. Refused, changing nothing: a particle out of range or given twice, a rest point not
  /// finite, a rest shape on one line or at one point (no rotation to fit), a bad compliance.
  int64_t add_shape_match(Id group, std::span<const int32_t> particles, std::span<const Vec3> rest, double compliance);
  /// Removes a group's shape match; the ones after it move down by one.
  void remove_shape_match(Id group, int64_t index);
  /// A group's shape matches (null = the default group), in the order added.
  const std::vector<ShapeMatch>& shape_matches(Id group) const;
  /// The constraints broken since the last call, in the order they broke; the list is emptied.
  std::vector<BrokenConstraint> take_broken();
  const std::vector<BrokenConstraint>& broken() const { return broken_; }
  /// A disabled group keeps its constraints and soft pins but is not projected, measured or
  /// diagnosed until enabled again. The contact group is always enabled.
  void set_group_enabled(Id group, bool enabled);
  /// A body's material, from the next step on: the compliances of the constraints it generated,
  /// and its particles' damping, thickness and friction. Its mass and density are refused: the
  /// particles' masses were set from them at creation.
  void set_material(Id body, const Material& material);
  /// The masses (kg) of a body's particles, one per particle, from the next step on: 0 makes a
  /// particle immovable (an anchor, as at creation), else each in [1e-300, 1e300]. A hard-pinned
  /// particle keeps following its pin; its new mass applies once the pin is gone. The body's
  /// material (mass, density) stays as it was: it says how the creation masses were computed.
  void set_masses(Id body, std::span<const double> masses);

  // --- pins ------------------------------------------------------------------------------------
  Id create_pin(const PinDesc& desc);
  void destroy_pin(Id id);
  void set_pin_target(Id id, const Vec3& target);
  const Pin& pin(Id id) const;
  size_t pin_count() const;

  // --- colliders -------------------------------------------------------------------------------
  Id create_collider(const ColliderDesc& desc);
  void destroy_collider(Id id);
  void set_collider_transform(Id id, const Vec3& position, const Eigen::Quaterniond& rotation);
  const Collider& collider(Id id) const;
  size_t collider_count() const;

  // --- panel meshes (panels.hpp builds them) ----------------------------------------------------
  /// Marks `layout.body` as a panel mesh (layout.first_particle is taken from the body). Refused
  /// unless the body has exactly 8 particles per panel, the quads index [0, vertex_count) with four
  /// distinct vertices each, and the thickness is positive and finite; a body has one layout.
  void set_panel_layout(const PanelLayout& layout);
  /// The layout of a panel-mesh body, or nullptr if the body is not one.
  const PanelLayout* panel_layout(Id body) const;
  const std::vector<PanelLayout>& panel_layouts() const { return panel_layouts_; }

  // --- particles -------------------------------------------------------------------------------
  int32_t particle_count() const { return static_cast<int32_t>(x_.size()); }
  const std::vector<Vec3>& positions() const { return x_; }
  const std::vector<Vec3>& velocities() const { return v_; }
  const std::vector<double>& inverse_masses() const { return inv_mass_; }
  /// Every group, pin and collider slot, live or not (check `alive`), for saving and inspection.
  const std::vector<Group>& groups() const { return groups_; }
  const std::vector<Pin>& pins() const { return pins_; }
  const std::vector<Collider>& colliders() const { return colliders_; }
  /// Every field slot, live or not (check `alive`).
  const std::vector<Field>& fields() const { return fields_; }
  /// Sets the frame counter and simulated time (a saved scene continuing where it stopped).
  void set_clock(int64_t frame, double time);
  void set_positions(int32_t first, std::span<const double> xyz);
  void set_velocities(int32_t first, std::span<const double> xyz);
  /// Point loads (N, xyz per particle) on particles [first, first + size / 3): forces applied every
  /// substep beside gravity until changed; 0 by default. Each coordinate finite, |c| <= 1e300.
  void set_loads(int32_t first, std::span<const double> xyz);
  const std::vector<Vec3>& loads() const { return load_; }
  /// Replaces the area loads (loads.hpp) with `loads` (empty: none), from the next step on. Refused,
  /// changing nothing: a particle out of range, a repeated corner (a degenerate triangle), an
  /// unknown mode, a pressure not finite within +-1e300, a direction not finite or, for the fixed
  /// modes, zero (or too short to normalise).
  void set_area_loads(std::span<const AreaLoad> loads);
  const std::vector<AreaLoad>& area_loads() const { return area_loads_; }
  /// Replaces the line loads (loads.hpp), checked likewise (an edge joining a particle to itself
  /// is degenerate).
  void set_line_loads(std::span<const LineLoad> loads);
  const std::vector<LineLoad>& line_loads() const { return line_loads_; }
  /// Throws as set_area_loads / set_line_loads would for this one load (`what` names it).
  void check_area_load(const AreaLoad& load, const std::string& what) const;
  void check_line_load(const LineLoad& load, const std::string& what) const;
  /// The total load on every particle at the current positions (N): its point load plus its share
  /// of every area and line load (a third of a triangle's, half an edge's). Weight not included.
  std::vector<Vec3> applied_loads() const;

  // --- fields (fields.hpp) -------------------------------------------------------------------
  Id create_field(const FieldDesc& desc);
  void destroy_field(Id id);
  const Field& field(Id id) const;
  size_t field_count() const;
  /// A field's parameters, from the next step on, checked as create_field checks them; its kind
  /// and body are those it was created with (a desc naming others is refused).
  void set_field(Id id, const FieldDesc& desc);

  // --- stepping --------------------------------------------------------------------------------
  /// Advances one frame of settings().dt. A frame that does not complete leaves the world as the
  /// call found it, including what `control.before_frame` changed: on a non-finite state it records
  /// a Warning and throws Error(numerical); when `*control.cancel` is found set (between
  /// iterations) it throws Error(cancelled); any other exception passes through the same way.
  void step(const StepControl& control = {});
  const StepReport& report() const { return report_; }
  // Diagnostics of the last step (solver/diagnose.cpp): which constraints are fighting.
  /// The `count` constraints and soft pins ranked by violation times force (J for every kind: a length
  /// times a force, an angle times a torque, a volume times a pressure), the residual breaking ties.
  std::vector<ConstraintResidual> worst_constraints(size_t count) const;
  /// Every pair of groups whose forces on shared particles oppose, largest force first.
  std::vector<GroupConflict> group_conflicts() const;
  /// The residual of every constraint of `kind` in `group`, in the group's ConstraintArray order.
  std::vector<double> constraint_residuals(Id group, Kind kind) const;
  // Statics of the last step (solver/statics.cpp): forces from the last substep's multipliers.
  /// The force of every constraint of `kind` in `group`, -lambda / h^2 of the last substep, in the
  /// group's ConstraintArray order: for a distance or tether its tension (N, positive pulling the
  /// ends together). Refused for a weld (three multipliers: its force is a vector).
  std::vector<double> constraint_forces(Id group, Kind kind) const;
  /// The force every live pin exerts on its particle (N), pins in slot order. A soft pin or a
  /// sliding support: its multiplier over h^2. A hard point pin: minus the sum of the particle's weight, its point load
  /// and the forces of every constraint, automatic tether and soft pin on it (the pin holds the rest).
  std::vector<Reaction> reactions() const;
  /// The force every live collider exerts on the world (N), colliders in slot order, from the last
  /// substep's contacts: a particle contact pushes m lambda / h^2 along its normal (its lambda is a
  /// length), a panel face contact b_k lambda / h^2 along its normal on each movable corner pair k,
  /// each normal taken where the solve left the particles; friction and the push back onto the
  /// surface add the force whose displacement they gave (Contact::force_h2 / h^2). The moment is
  /// about the collider's position, each force acting at its particle (a face contact: its contact
  /// point).
  std::vector<ColliderReaction> collider_reactions() const;
  /// What those readers read (StaticsState), for saving: every (group, kind) and group's automatic
  /// tethers with a multiplier that is not +0, every pin whose multiplier is not +0, and the contacts
  /// with a force on a live collider, each in the order the readers sum them.
  StaticsState statics_state() const;
  /// Replaces it (a saved scene's state.forces, loaded): the solver arrays are brought up to date
  /// first, as the next step would (a world edited since its last step has them rebuilt, its
  /// multipliers 0, whether or not `state` is then accepted), then every multiplier and contact
  /// force is set from `state` and those it does not list to 0. Refused, changing no multiplier or
  /// contact beyond that rebuild: a stale group, pin or collider, a kind listed twice for a group
  /// (or a group's tethers twice, a pin twice), a count that is not multipliers(kind) per constraint
  /// of the group's kind (one per automatic tether), a hard pin (it keeps no multiplier), a particle
  /// out of range, a value not finite within +-1e300.
  void set_statics_state(const StaticsState& state);
  const Warning& warning() const { return warning_; }

 private:
  Group& group_mut(Id id);
  /// The constraint array a constraint is in (refused: stale group, unknown kind, index out of range).
  const ConstraintArray& constraint_array(Id group, Kind kind, int64_t index) const;
  /// The same, for an edit: a generated constraint is refused too.
  ConstraintArray& edited_array(Id group, Kind kind, int64_t index);
  /// A field desc checked as create_field and set_field take it (a pressure's rest volume 0
  /// measured now).
  FieldDesc checked_field(const FieldDesc& desc) const;
  const Group* find_group(Id id) const;
  Id resolve_group(Id id) const;
  void check_particle(int64_t index, const char* what) const;
  void refresh_rest();
  void rebuild_solver();
  void rebuild_order();
  void predict(double h, double alpha);
  void move_colliders(double alpha);
  void find_contacts();
  void find_self_contacts();
  void find_face_contacts();
  void project_face_contacts();
  /// One Chebyshev acceleration step after iteration `iteration` of a substep (solver/step.cpp).
  void chebyshev_step(int iteration, double rho, double& omega);
  /// Inverse of the joint mass of a panel corner and its partner across the slab (0: one is fixed).
  double slab_weight(int32_t a, int32_t b) const;
  // Contacts of one collider with every movable particle, or with those listed in `only`.
  /// Contacts of `collider` with every particle (or those of `only`), appended to `out` in particle
  /// order; the particles are split over the threads, each part's contacts appended in turn.
  void find_collider_contacts(int32_t collider, const std::vector<int32_t>* only, std::vector<Contact>& out);
  /// The same for the particles [begin, end) of the list (all particles, or `only`).
  void find_collider_contacts(int32_t collider, const std::vector<int32_t>* only, size_t begin, size_t end,
                              std::vector<Contact>& out) const;
  void find_shape_contacts(int32_t collider, const std::vector<int32_t>* only, size_t begin, size_t end,
                           std::vector<Contact>& out) const;
  void catch_late_contacts();
  void settle_contacts_on_surface();
  void project_contact(Contact& ct);
  void reset_multipliers();
  void realign(const std::vector<Vec3>& predicted);
  // The impulse each hard pin takes in the last substep of a frame (its Pin::lambda, solver/statics.cpp
  // "Hard pins"): the constraints holding a hard-pinned particle, listed in SolverArray::pinned
  // whenever the solver arrays are rebuilt (a hard pin's creation or removal rebuilds them), and
  // whether there are any; whether they are tracked in this substep; the impulses set from the
  // multipliers at a realignment; the impulses at iterations k - 1 and k (Chebyshev acceleration
  // moves them as it moves positions).
  void find_pinned_slots();
  void restart_pin_impulses();
  bool pinned_any_ = false, track_pins_ = false;
  std::vector<Vec3> pin_chebyshev_prev_, pin_chebyshev_now_;
  /// Projects a group once; `first`: its first projection in the substep (the chain solve's turn).
  /// `ends`: IslandEnds, the group's first and last projection in a pass of the iterations.
  void project_group(Group& g, double h, bool first, int ends);
  void project_contacts(Group& g, double h);
  /// Settings::global_solve: the substep's implicit problem solved by Newton's method, the
  /// multipliers set from it (solver/global_solve.cpp).
  void global_step(double h);
  /// One sweep over the global solve's rows at x (global_solve.cpp says what each pass does).
  void global_terms(const std::vector<Vec3>& x, double inv_h2, int pass, double t, bool matrix, bool store);
  // The step's stages (step.cpp lists them in order).
  void begin_frame(const StepControl& control);
  /// `last`: the frame's last substep, where the islands give their multipliers back (IslandEnds).
  void solve(double h, const StepControl& control, bool last);
  void apply_friction(double h);
  void apply_collider_friction(Contact& contact, double h);  // one collider contact's (apply_friction)
  void update_velocities(double h);
  // Throws Error(numerical), with a Warning, at the first particle whose position or velocity is
  // non-finite or beyond limits::kMaxAbsValue.
  void check_state_in_range();
  void end_frame();
  void measure();
  void apply_plasticity();  // model/plasticity.cpp
  /// What a frame that does not complete restores (step): the state, the last completed frame's
  /// contacts (saved with the world: the statics read their forces), and the pin targets, collider
  /// poses, gravity and rest scales that StepControl::before_frame may change.
  struct FrameStart {
    std::vector<Vec3> x, v;
    std::vector<Contact> contacts;  // the contact group's
    std::vector<SelfContact> self_contacts;
    std::vector<FaceContact> face_contacts;
    std::vector<Vec3> pin_lambda, pin_target;
    std::vector<Vec3> collider_position;
    std::vector<Eigen::Quaterniond> collider_rotation;
    std::vector<std::array<double, 3>> rest_scale;
    std::vector<std::vector<double>> tether_lambda;  // per group slot: the automatic tethers' multipliers
    Vec3 gravity = Vec3::Zero();
  };
  FrameStart frame_start() const;
  void restore(const FrameStart& start);
  void apply_fields(double h, double time);  // fields/fields.cpp: field forces into v_ (movable particles)
  void project_volumes(double h);            // fields/fields.cpp: the pressure fields' volume constraints

  Settings settings_;
  // particle state and per-particle model
  std::vector<Vec3> x_, x_prev_, v_;
  std::vector<double> inv_mass_;  // model: 0 = immovable
  std::vector<double> w_;         // solver: inverse mass with hard pins as 0
  std::vector<double> radius_;    // contact offset (half the body's thickness)
  std::vector<double> damping_;   // per-particle damping rate (1/s)
  std::vector<Vec3> load_;        // per-particle point load (N)
  std::vector<AreaLoad> area_loads_;
  std::vector<LineLoad> line_loads_;
  std::vector<Vec3> load_now_;  // scratch: point loads plus distributed loads at the substep's start
  /// Adds every area and line load's share at positions x to f (one entry per particle), in list
  /// order (area loads first), so the sums are the same bits run after run.
  void add_distributed_loads(const std::vector<Vec3>& x, std::vector<Vec3>& f) const;
  std::vector<double> mu_s_, mu_k_;
  std::vector<int32_t> body_of_;
  std::vector<int32_t> hard_pin_of_;  // pin slot or -1

  std::vector<BodyInfo> bodies_;
  std::vector<Group> groups_;
  std::vector<int32_t> order_;  // live, enabled group slots in projection order
  std::vector<Pin> pins_;
  std::vector<Collider> colliders_;
  std::vector<PanelLayout> panel_layouts_;
  Id default_group_;
  int64_t serial_ = 0;
  struct TetherCache {  // a body's automatic tethers, kept while its anchors stay the same
    std::vector<int32_t> anchors;
    int32_t per_particle = 0;
    std::vector<Attachment> links;
  };
  std::vector<TetherCache> tether_cache_;  // one per body
  bool rest_dirty_ = true;
  bool solver_dirty_ = true;
  std::vector<BrokenConstraint> broken_;
  std::vector<SelfContact> self_contacts_;  // this substep's (Settings::self_collision)
  std::vector<FaceContact> face_contacts_;  // this substep's panel faces against spheres
  SelfCollisionCache self_cache_;
  std::vector<Vec3> detected_;  // positions when this substep's contacts were found
  /// Settings::chain_solve's scratch: per link of the longest chain, 9 values for each of (at most)
  /// 4 lanes, and per particle 4 for each lane (the chain step, solver/kernels.cpp).
  static constexpr size_t kChainScratch = 52;
  std::vector<double> measure_values_;                // measure(): one array's constraint values
  std::vector<double> chain_scratch_;                 // per thread: kChainScratch per link of the longest chain, + 1
  std::unique_ptr<ThreadPool> pool_;                  // Settings::threads
  std::unique_ptr<GlobalSolve> global_;               // Settings::global_solve: pattern, factorisation, scratch
  std::vector<std::vector<Contact>> contact_parts_;   // find_collider_contacts: one list per thread
  std::vector<std::vector<FaceContact>> face_parts_;  // find_face_contacts: one list per thread
  /// find_face_contacts' bounds over one frame's substeps: per sphere, layout and panel, how far
  /// its faces were at least from the sphere (less its radius) when last looked at, plus `spent`
  /// then (-inf: not yet); per sphere and layout, `spent`: what such a bound can have lost since the
  /// frame began; and where the spheres and the layouts' particles were at the last look.
  struct FaceReach {
    bool started = false;
    std::vector<double> bound, spent;
    std::vector<Vec3> sphere, seen;
    std::vector<std::pair<double, double>> shifts;  // per layout: this substep's (see find_face_contacts)
  } face_reach_;
  std::vector<int32_t> late_moved_;                   // catch_late_contacts: the particles looked at again
  std::vector<uint8_t> late_watched_;                 // catch_late_contacts: per particle, whether a contact watched it
  std::vector<Vec3> chebyshev_prev_, chebyshev_now_;  // Settings::chebyshev_rho_milli: x^(k-1), x^k
  // The per-particle passes' parts, where a group's islands go in colours over several threads
  // (find_particle_parts): (begin, end, part) runs of particles, each particle in the part of the
  // thread that projects its first island, so that a thread's passes over its particles read what
  // it wrote itself. Empty: the passes cut the particles into equal ranges.
  std::vector<std::array<int32_t, 3>> particle_runs_;
  void find_particle_parts();
  std::vector<Vec3> predicted_, realign_;  // realignment scratch (Settings::realign_passes)
  std::vector<double> shape_weights_;      // project_shape_match's scratch
  StepReport report_;
  Warning warning_;
  std::vector<Field> fields_;
  std::vector<Vec3> field_force_;  // scratch: per-particle field force (N)
};

}  // namespace embra
