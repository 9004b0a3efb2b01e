/*
 * embra.h - the C ABI of embra, a unified constraint solver for interactive form finding.
 *
 * This header is the manual. embra simulates cloth, membranes, rods, solids and fabrication
 * constraints as particles under constraints, stepped with XPBD (extended position based dynamics)
 * in substeps. A host (a CAD plugin, a Python or C# script, the `embra` command) builds a world,
 * steps it every frame and reads the positions back.
 *
 * HOW TO START
 *
 *     if (embra_check_abi(EMBRA_ABI_VERSION) != EMBRA_OK) { ...header and library disagree... }
 *     embra_world* world = NULL;
 *     embra_solver_def solver = embra_default_solver_def();
 *     solver.gravity[2] = +9.81;                       // reversed gravity: the Gaudi paradigm
 *     embra_world_create(&world, &solver);
 *
 *     embra_body_def body = embra_default_body_def();   // a cloth from a triangle mesh
 *     body.vertex_count = n; body.positions = xyz;      // double[3 * n], metres
 *     body.triangle_count = t; body.triangles = tri;    // int32_t[3 * t], 0-based
 *     body.material.mass = 1.0;                          // kg, spread over the area
 *     embra_body_id cloth; int32_t first = 0;
 *     embra_body_create(world, &body, &cloth, &first);  // stretch + bend constraints generated
 *
 *     embra_pin_def pin = embra_default_pin_def();       // hold a corner where it is
 *     pin.particle = first + corner; memcpy(pin.target, &xyz[3 * corner], sizeof pin.target);
 *     embra_pin_id corner_pin; embra_pin_create(world, &pin, &corner_pin);
 *
 *     for (;;) {                                         // every frame
 *       embra_world_step(world);
 *       embra_world_get_positions(world, out_xyz, 3 * n, first, n);
 *     }
 *     embra_world_destroy(world);
 *
 * UNITS
 *   SI by convention: metres, kilograms, seconds, newtons, radians. Compliance is the inverse of
 *   stiffness (0 = rigid): m/N for lengths, rad/(N m) for angles, m^3/N for volumes, m/N for pins.
 *
 * ERRORS
 *   Every function that can fail returns an embra_status: EMBRA_OK (0) or a negative code. The
 *   message of the last failure on the calling thread is embra_last_error_message(), never NULL.
 *   A refused call changes nothing: every argument is checked before anything is modified.
 *   No exception, abort or C++ object ever crosses this boundary. Numerical trouble in a step
 *   (a position or velocity non-finite or beyond EMBRA_MAX_ABS_VALUE, which no scene could hold)
 *   restores the world to its state before the step, returns EMBRA_ERROR_NUMERICAL and records an
 *   embra_warning.
 *
 * RANGES AND LIMITS
 *   Every number a world accepts is finite and within +-EMBRA_MAX_ABS_VALUE (1e300); values that
 *   must be positive (dt, densities, sizes) are at least EMBRA_MIN_POSITIVE (1e-300), and masses
 *   are 0 (immovable, where allowed) or at least EMBRA_MIN_POSITIVE, so every inverse is finite.
 *   These are the scene schema's ranges too: whatever the C API accepts, embra_world_save_json
 *   writes and embra_world_load_json reads back. A world holds at most EMBRA_MAX_PARTICLES
 *   particles and EMBRA_MAX_CONSTRAINTS constraints; a step does at most EMBRA_MAX_PASSES_PER_STEP
 *   substeps x iterations; dt is at most EMBRA_MAX_DT seconds. Beyond them: INVALID_ARGUMENT.
 *
 * THREADING
 *   One call at a time per world, enforced: a call made while another thread's call on the same
 *   world is in progress returns EMBRA_ERROR_LOCKED and changes nothing (it never waits). The
 *   one exception is embra_world_cancel, which any thread may call at any time. Different worlds
 *   may be used from different threads at once. The last-error message is per thread.
 *
 * IDS AND INDICES
 *   Groups, pins and colliders are small value ids {index, generation}: a destroyed object's id
 *   is refused with EMBRA_ERROR_STALE_ID, never reused. A zeroed id ({0, 0}) means "none" or
 *   "the default" where a field says so. Particles are dense int32 indices into the world, in
 *   creation order: a body's particles are [first, first + vertex_count).
 *
 * BUFFERS
 *   Bulk data is flat xyz double arrays owned by the caller. Reads take the buffer's capacity in
 *   doubles; too small a buffer returns EMBRA_ERROR_BUFFER_TOO_SMALL and writes nothing.
 *
 * DEFS
 *   Anything with more than three parameters is an embra_*_def struct. Get one from its
 *   embra_default_*_def() function, change the fields you need, pass its address. The first field
 *   is the struct's version; fields are only ever appended.
 *
 * STABILITY
 *   EMBRA_ABI_VERSION changes only when a compiled host would break. Call embra_check_abi() first.
 */
#ifndef EMBRA_EMBRA_H
#define EMBRA_EMBRA_H

#include <stdint.h>

#include "embra/embra_export.h"
#include "embra/embra_version.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---------------------------------------------------------------------------------------------
 * Status codes
 * ------------------------------------------------------------------------------------------- */

typedef int32_t embra_status;
enum {
  EMBRA_OK = 0,
  EMBRA_ERROR_INVALID_ARGUMENT = -1, /* null, out of range, non-finite, wrong count, degenerate */
  EMBRA_ERROR_STALE_ID = -2,         /* an id of a destroyed object, or of another world */
  EMBRA_ERROR_BUFFER_TOO_SMALL = -3, /* an output buffer cannot hold the result; nothing written */
  EMBRA_ERROR_SCHEMA = -4,           /* a JSON document does not match its schema */
  EMBRA_ERROR_VERSION = -5,          /* header and library (or a def's version) disagree */
  EMBRA_ERROR_LOCKED = -6,           /* the world is in use by a call in progress */
  EMBRA_ERROR_NUMERICAL = -7,        /* the step produced a non-finite state, or one beyond
                                        EMBRA_MAX_ABS_VALUE; world restored */
  EMBRA_ERROR_INTERNAL = -8,         /* a bug in embra, or out of memory; message says which */
  EMBRA_ERROR_CANCELLED = -9         /* embra_world_cancel stopped the step; world restored */
};

/* The ranges and limits above (the scene schema states the same numbers; a test compares them). */
#define EMBRA_MAX_ABS_VALUE 1e300
#define EMBRA_MIN_POSITIVE 1e-300
#define EMBRA_MAX_DT 1e6
#define EMBRA_MAX_UNIT_SCALE 1e12
#define EMBRA_MAX_PARTICLES 2097152
#define EMBRA_MAX_CONSTRAINTS 16777216
#define EMBRA_MAX_PASSES_PER_STEP 100000
#define EMBRA_MAX_OBJ_BYTES 268435456
#define EMBRA_MAX_THREADS 256
/* embra_solver_def.global_solve: 2 turns the global solve on in a world without colliders or
   self-collision while its system has at most EMBRA_GLOBAL_SOLVE_AUTO_LIMIT unknowns (3 per movable
   particle plus one per constraint row). */
#define EMBRA_GLOBAL_SOLVE_AUTO 2
#define EMBRA_GLOBAL_SOLVE_AUTO_LIMIT 20000

/* The message of the last failed call on this thread ("" if none). Never NULL; valid until the
 * next embra call on this thread. At most EMBRA_MAX_ERROR_MESSAGE bytes with its terminating zero:
 * a longer one is cut before the character that does not fit. */
#define EMBRA_MAX_ERROR_MESSAGE 4096
EMBRA_API const char* embra_last_error_message(void);

/* A short constant name for a status code, e.g. "EMBRA_ERROR_STALE_ID". Never NULL. */
EMBRA_API const char* embra_status_name(embra_status status);

/* ---------------------------------------------------------------------------------------------
 * Versions
 * ------------------------------------------------------------------------------------------- */

/* The library's version as MAJOR * 10000 + MINOR * 100 + PATCH. */
EMBRA_API int32_t embra_version(void);
/* The library's version as a string "MAJOR.MINOR.PATCH". Never NULL, static. */
EMBRA_API const char* embra_version_string(void);
/* The library's ABI version (the SONAME's number). */
EMBRA_API int32_t embra_abi_version(void);
/* EMBRA_OK when `header_abi_version` (pass EMBRA_ABI_VERSION) matches the library, else
 * EMBRA_ERROR_VERSION. Hosts call this once before anything else. */
EMBRA_API embra_status embra_check_abi(int32_t header_abi_version);

/* ---------------------------------------------------------------------------------------------
 * Ids
 * ------------------------------------------------------------------------------------------- */

typedef struct embra_world embra_world; /* opaque; create and destroy with the functions below */

typedef struct embra_group_id {
  uint32_t index;
  uint32_t generation;
} embra_group_id;
typedef struct embra_body_id {
  uint32_t index;
  uint32_t generation;
} embra_body_id;
typedef struct embra_pin_id {
  uint32_t index;
  uint32_t generation;
} embra_pin_id;
typedef struct embra_collider_id {
  uint32_t index;
  uint32_t generation;
} embra_collider_id;

/* ---------------------------------------------------------------------------------------------
 * World and solver settings
 * ------------------------------------------------------------------------------------------- */

#define EMBRA_SOLVER_DEF_VERSION 2
typedef struct embra_solver_def {
  int32_t version;             /* EMBRA_SOLVER_DEF_VERSION */
  int32_t substeps;            /* substeps per frame, [1, 10000]; default 16 (small steps converge
                                  stiff cloth far better than iterations at the same cost) */
  double dt;                   /* s per frame (per embra_world_step), > 0; default 1/60 */
  int32_t iterations;          /* passes over the ordered groups per substep, [1, 10000]; default 1 */
  int32_t chebyshev_rho_milli; /* [0, 990], default 0 (off). Chebyshev semi-iterative acceleration of
                             the iterations (Wang 2015): from the third iteration of each pass
                             (1 + realign_passes per substep) to the last but one, each iteration's result x is pushed
                             on to omega (x - x_prev2) + x_prev2 (the last stays a plain pass: contacts keep the final
                             word), omega from the estimated spectral radius rho = chebyshev_rho_milli / 1000 of the
                             Gauss-Seidel pass. For many iterations over stiff, long chains of constraints (large panel
                             meshes): 900 reaches the accuracy of 2 to 2.5x the iterations. Too large a rho diverges (on
                             the 16 x 16 panel drape 930 holds and 950 does not); no effect with 1 to 3 iterations. */
  double gravity[3];           /* m/s^2; default {0, 0, -9.81} (z up). Any direction: negate to hang */
  double damping;              /* 1/s, velocity decay rate applied to every particle; >= 0; default 0 */
  double settle_speed;         /* m/s: a frame is "settled" when no particle moves faster; default 1e-3 */
  int32_t tethers;             /* automatic long-range attachments, [0, 64]; default 2. Each movable
                                  particle of a body with hard-pinned particles is tied to its `tethers`
                                  nearest pinned ones by a one-sided tether whose rest is the length of a
                                  path over the body's rest surface (never shorter than the geodesic, so it
                                  never holds back a shape the cloth can take): a hanging cloth cannot
                                  stretch far from its pins whatever the iteration count. A particle's
                                  tethers are projected together, to the nearest point inside all of
                                  them (one after another when realign_passes > 0). 0 = none */
  int32_t realign_passes;      /* [0, 100], default 0 (textbook XPBD). XPBD drops a term of the implicit
                                  step (Macklin et al. 2016, eq. 11), so a settled structure sits off
                                  its exact static equilibrium by O(h^2 g). Each pass re-derives the
                                  positions from the multipliers with the current gradients and
                                  iterates again: with 2-4 passes a settled form is the equilibrium to
                                  rounding (the hanging chain matches the discrete catenary to 3e-12).
                                  Costs (1 + passes) x the iterations. */
  int32_t self_collision;      /* 0 (default) or 1. 1: cloth and shells (bodies with triangles) collide
                                  with themselves and with each other, point against triangle and edge
                                  against edge, kept the sum of the two sides' half thicknesses apart
                                  (embra_material.thickness), found in space-time over each substep so
                                  fast folds never pass through, resolved as hard contacts in the contact
                                  group with the materials' friction. The broad phase keeps its candidate
                                  pairs while the particles stay in regions around their motion and
                                  finds those of the particles that leave in a bounding-volume
                                  hierarchy (cost linear in the particle count). */
  int32_t chain_solve;         /* 0 or 1; default 1. 1: distance constraints that lie end to end in
                                  straight runs over the bodies' rest shapes (a cloth grid's rows,
                                  columns and diagonals; any mesh's straight edge runs, within about
                                  26 degrees a joint) or through particles where only two of a group's
                                  distances meet and no third joins their far ends (a cable or chain,
                                  at any angle; not a triangle's corner) are projected a run
                                  at a time in the first iteration of every substep (with realignment
                                  passes, the cables only, before the first pass), each run's
                                  linearised XPBD system solved
                                  exactly (tridiagonal, cost linear in its length): a Newton step for
                                  the whole run, so a correction travels the run in one pass instead of
                                  one link per pass. A step that does not lower the run's residual (a
                                  run folded over, rest lengths cut to a fraction) is dropped for
                                  one-at-a-time projection. Later iterations and the realignment passes
                                  (realign_passes > 0) project one constraint at a time: repeated
                                  Newton steps in one substep leave a taut structure sliding along its
                                  constraints (a 64-link catenary at 2 substeps x 40 iterations kept
                                  2 cm/s against damping 20/s). Measured: the 128 x 128 hanging cloth
                                  after 200 frames at 16 substeps, 37 % -> 0.60 % max edge strain
                                  (bench/README.md); a 64-link catenary at 20 x 1 settles 2,000 times
                                  closer to the exact discrete catenary, and with 2 realignment passes
                                  on it to 3e-9 of the span (3.6e-3 with one constraint at a time).
                                  0: one constraint at a time throughout. */
  int32_t threads;             /* threads the solver uses, the caller's included, [0,
                                  EMBRA_MAX_THREADS]; default 1.
                                  0: one per core of the machine. Each colour of constraints (and of
                                  chains, tethers and residuals) is split over them; the result is the
                                  same bits at any count, so this changes only the time a step takes
                                  (128 x 128 cloth: 27.5 ms/frame on 1 thread, 17.1 on 2). The threads
                                  wait for work between steps without using the CPU */
  int32_t global_solve;        /* 0 (default), 1 or EMBRA_GLOBAL_SOLVE_AUTO (2). 1: each substep is first
                                  solved as one system (the global solve): XPBD's implicit step over
                                  every constraint and soft pin of the enabled groups, found by Newton's
                                  method on its equations, one sparse LDL^T factorisation per Newton
                                  iteration (up to 24 a substep; 2-10 at rest), with the geometric
                                  stiffness of lengths in tension. Only steps that lower the residual
                                  are taken, so it cannot blow up. The multipliers are set from it and
                                  the `iterations` run on from there, groups in their order and weight
                                  (they have the final word: contacts, pressure volumes, fields and the
                                  automatic tethers act in them). A load carried across a net, a cable or
                                  a stiff structure needs no iterations to travel: a settled form is its
                                  exact statics whatever its size (a 64-link chain on the discrete
                                  catenary to 4.9e-7 of its span, a 32 x 32 net's nodes in equilibrium
                                  to 4.3e-13 of their weight, at the form-finding preset). A distance
                                  compressed by more than 0.1 % is slack in it (the iterations push it
                                  back). Contacts are not rows of it: with colliders it pulls into them
                                  what the contacts push out (the 4 x 4 POQ drape at the preset with it
                                  never came to rest). One thread; its cost grows faster than the
                                  system's size. 2 turns it on only in a world without colliders or
                                  self-collision and while the system has at most
                                  EMBRA_GLOBAL_SOLVE_AUTO_LIMIT unknowns, as the form-finding preset
                                  does. This field was reserved0 (always 0) before: hosts that zero it
                                  keep the iterations alone. */
} embra_solver_def;

EMBRA_API embra_solver_def embra_default_solver_def(void);
/* The form-finding preset: the defaults with dt 1/15 s, 1 substep, 1 iteration, damping 6/s and
 * global_solve EMBRA_GLOBAL_SOLVE_AUTO, for the shape a structure comes to rest in rather than the
 * motion on the way: every scene built with it comes to rest (embra_world_solve says whether within
 * tolerance). Measured with no tuning (tests/unit/form_finding_test.cpp, FormFinding.ThePreset*):
 * a chain of 64 links built by hand on an arc is at rest on the discrete catenary to 4.9e-7 of its
 * span after 16 frames, its links at their length to 3e-17; a 32 x 32 net of links hung from its
 * corners drawn in to 70 % is at rest after 30 frames, its links at length to 1.3e-16 m and every node
 * in equilibrium (weight against link tensions) to 4.3e-13 of its weight. Both go through the global
 * solve (their systems are small); a large cloth goes through the iterations alone, where large steps,
 * the chain solve and the tethers keep it near inextensible: the 128 x 128 cloth hanging from two
 * corners is at rest (max speed under 1 mm/s, strain under 1 %, held 30 frames) after 44 frames,
 * against 185 frames at the defaults (BM_ClothToRest). Without the global solve (global_solve 0) the
 * same chain comes to rest stretched and embra_world_solve reports it settled out of tolerance. */
EMBRA_API embra_solver_def embra_form_finding_solver_def(void);

/* Creates an empty world with a default group (order 0, weight 1) and a contact group
 * (order 1000, weight 1). `def` may be NULL for the defaults. On failure *out_world is NULL. */
EMBRA_API embra_status embra_world_create(embra_world** out_world, const embra_solver_def* def);
/* Destroys a world and everything in it. NULL is accepted and ignored. */
EMBRA_API void embra_world_destroy(embra_world* world);

/* Reads or replaces the solver settings (between steps). */
EMBRA_API embra_status embra_world_get_solver(const embra_world* world, embra_solver_def* out_def);
EMBRA_API embra_status embra_world_set_solver(embra_world* world, const embra_solver_def* def);
/* Sets gravity (m/s^2) between steps; reversing it is the Gaudi paradigm. The host takes over: a
 * scene's gravity changes (actions) stop. */
EMBRA_API embra_status embra_world_set_gravity(embra_world* world, const double gravity[3]);

typedef struct embra_world_counts {
  int32_t particles;
  int32_t bodies;
  int32_t groups;    /* live groups, including the default and contact groups */
  int32_t pins;      /* live pins */
  int32_t colliders; /* live colliders */
  int32_t reserved0;
  int64_t constraints; /* all constraints in live groups (pins and contacts not counted) */
} embra_world_counts;

EMBRA_API embra_status embra_world_get_counts(const embra_world* world, embra_world_counts* out_counts);

/* The ids of the live objects of one kind, in creation order: for a world loaded from a scene, the
 * order of the scene's arrays (groups: "default" and "contacts" first, then the scene's; a panel
 * mesh's body and pins after the scene's bodies and pins, as saved), so a host that reads the scene
 * JSON (embra_world_save_json) pairs its entries with these ids. Two-call pattern: out NULL and
 * capacity 0 only write *out_count; too small a buffer is EMBRA_ERROR_BUFFER_TOO_SMALL, nothing
 * written. Capacity and *out_count are in ids. */
EMBRA_API embra_status embra_world_get_bodies(const embra_world* world, embra_body_id* out, int32_t capacity,
                                              int32_t* out_count);
EMBRA_API embra_status embra_world_get_groups(const embra_world* world, embra_group_id* out, int32_t capacity,
                                              int32_t* out_count);
EMBRA_API embra_status embra_world_get_pins(const embra_world* world, embra_pin_id* out, int32_t capacity,
                                            int32_t* out_count);
EMBRA_API embra_status embra_world_get_colliders(const embra_world* world, embra_collider_id* out, int32_t capacity,
                                                 int32_t* out_count);

/* ---------------------------------------------------------------------------------------------
 * Groups: the paper's "preferred order of evaluation" and "importance weight"
 *
 * Every constraint belongs to a group. In each substep the groups are projected in increasing
 * `order` (ties in creation order), each `weight` times in a row, and that whole pass is repeated
 * `iterations` times. Put collisions last so they take precedence (the contact group's order is
 * 1000); give a group a higher weight to make it win over the others. Within one group the kinds
 * go in a fixed order: soft pins, welds, bending (edge angle, dihedral), tethers, stretch
 * (distance), volume, equal lengths, conical vertices, the geometry goals (length_min, angle_min,
 * angle_max, colinear, direction, cocircular, cospherical, in that order), panels (planarity,
 * offsets), contacts; a later kind has the final word.
 * ------------------------------------------------------------------------------------------- */

#define EMBRA_GROUP_DEF_VERSION 1
typedef struct embra_group_def {
  int32_t version; /* EMBRA_GROUP_DEF_VERSION */
  int32_t order;   /* any int32; lower goes first; default 0 */
  int32_t weight;  /* projections per pass, [1, 1000]; default 1 */
} embra_group_def;

EMBRA_API embra_group_def embra_default_group_def(void);
EMBRA_API embra_status embra_group_create(embra_world* world, const embra_group_def* def, embra_group_id* out_group);
/* Destroys a group and all its constraints. The default and contact groups cannot be destroyed;
 * a group that still holds soft pins is refused. */
EMBRA_API embra_status embra_group_destroy(embra_world* world, embra_group_id group);
EMBRA_API embra_status embra_group_set_order(embra_world* world, embra_group_id group, int32_t order);
EMBRA_API embra_status embra_group_set_weight(embra_world* world, embra_group_id group, int32_t weight);
/* Enables (1) or disables (0) a group. A disabled group keeps its constraints and soft pins but is
 * not projected, measured (embra_world_get_residuals, the settled test of embra_world_solve) or
 * diagnosed until enabled again; its report reads 0. Positions and velocities are untouched. The
 * contact group cannot be disabled. Saved in a scene as the group's "enabled". */
EMBRA_API embra_status embra_group_set_enabled(embra_world* world, embra_group_id group, int32_t enabled);
EMBRA_API embra_status embra_group_get_enabled(const embra_world* world, embra_group_id group, int32_t* out_enabled);
EMBRA_API embra_status embra_world_default_group(const embra_world* world, embra_group_id* out_group);
EMBRA_API embra_status embra_world_contact_group(const embra_world* world, embra_group_id* out_group);

/* ---------------------------------------------------------------------------------------------
 * Bodies: simplicial complexes (points, edges, triangles, tetrahedra) with a material
 * ------------------------------------------------------------------------------------------- */

/* m/s: the slip speed over which friction falls from its static to its dynamic coefficient
 * (mu = dynamic + (static - dynamic) exp(-speed / EMBRA_FRICTION_STRIBECK_SPEED)). */
#define EMBRA_FRICTION_STRIBECK_SPEED 0.01

typedef struct embra_material {
  double mass;               /* kg for the whole body, spread by lumped length/area/volume; used
                                when > 0. Default 0 (use density) */
  double density;            /* kg per unit of the body's highest-dimension measure (kg/m for
                                rods, kg/m^2 for cloth, kg/m^3 for solids); default 1 */
  double stretch_compliance; /* m/N on every edge; 0 = inextensible (default) */
  double shear_compliance;   /* rad/(N m) on triangle corner angles; default 0 */
  double bend_compliance;    /* rad/(N m) on dihedral angles; default 1 (soft cloth) */
  double volume_compliance;  /* m^3/N on tetrahedra; default 0 */
  double damping;            /* 1/s velocity decay of the body's particles; default 0 */
  double thickness;          /* m; particles keep half of it off colliders; default 0 */
  double friction_static;    /* against colliders (geometric mean with the collider's); 0.5. Coulomb
                                friction after each substep: a contact's slip is removed up to mu
                                times its push, mu falling continuously from friction_static at rest
                                to friction_dynamic as the slip speed passes
                                EMBRA_FRICTION_STRIBECK_SPEED */
  double friction_dynamic;   /* 0.3 */
} embra_material;

/* Which constraints embra_body_create generates from the elements (bit flags). */
enum {
  EMBRA_GENERATE_STRETCH = 1, /* a distance constraint on every unique edge (of edges, triangles
                                 and tetrahedra), rest = current length */
  EMBRA_GENERATE_SHEAR = 2,   /* an edge-angle constraint at each triangle corner */
  EMBRA_GENERATE_BEND = 4,    /* a dihedral constraint across every edge shared by two triangles,
                                 rest = current angle (so a curved rest shape keeps its curvature) */
  EMBRA_GENERATE_VOLUME = 8   /* a volume constraint on every tetrahedron */
};

#define EMBRA_BODY_DEF_VERSION 1
typedef struct embra_body_def {
  int32_t version;          /* EMBRA_BODY_DEF_VERSION */
  int32_t vertex_count;     /* > 0 */
  const double* positions;  /* double[3 * vertex_count], m; required */
  const double* masses;     /* double[vertex_count], kg (0 = immovable); NULL = from material */
  const double* uvs;        /* double[2 * vertex_count] material coordinates, or NULL; when given,
                               each edge's rest length is split into u and v parts so
                               embra_body_set_rest_scale can scale the directions separately */
  int32_t edge_count;       /* >= 0 */
  int32_t triangle_count;   /* >= 0 */
  const int32_t* edges;     /* int32_t[2 * edge_count], body-local vertex indices, or NULL */
  const int32_t* triangles; /* int32_t[3 * triangle_count], or NULL */
  const int32_t* tets;      /* int32_t[4 * tet_count], or NULL */
  int32_t tet_count;        /* >= 0 */
  int32_t generate;         /* EMBRA_GENERATE_* flags; default STRETCH | BEND | VOLUME */
  embra_material material;
  embra_group_id stretch_group; /* group of the generated constraints; {0,0} = default group */
  embra_group_id shear_group;
  embra_group_id bend_group;
  embra_group_id volume_group;
} embra_body_def;

EMBRA_API embra_material embra_default_material(void);
EMBRA_API embra_body_def embra_default_body_def(void);

/* Adds a body's vertices as particles [*out_first_particle, + vertex_count) and generates its
 * constraints. Refused (nothing added) for an index out of range, a repeated vertex within an
 * element, a zero-length edge, a zero-area triangle, a zero-volume tetrahedron, a non-finite
 * number or a negative material value. out_first_particle may be NULL. */
EMBRA_API embra_status embra_body_create(embra_world* world, const embra_body_def* def, embra_body_id* out_body,
                                         int32_t* out_first_particle);
/* The body's particle range. */
EMBRA_API embra_status embra_body_get_particles(const embra_world* world, embra_body_id body, int32_t* out_first,
                                                int32_t* out_count);
/* Scales the rest lengths of the body's generated stretch constraints (and volumes by scale^3)
 * from the next step on: rest = scale * |(scale_u * rest_u, scale_v * rest_v, rest_other)|, where
 * rest_u and rest_v are the parts of each edge along the body's uv directions (all of it is
 * "other" for a body without uvs). 1, 1, 1 is the rest shape; < 1 shrinks (shrink wrap, minimal
 * surfaces), > 1 grows (bounded growth). All >= 0 and finite. The host takes over: a scene's
 * rest-scale ramp for this body stops. */
EMBRA_API embra_status embra_body_set_rest_scale(embra_world* world, embra_body_id body, double scale, double scale_u,
                                                 double scale_v);
/* A body's material, from the next step on, without a rebuild: the compliances of the constraints
 * it generated (stretch, shear, bend, volume: a stiffness slider), its particles' damping,
 * thickness and friction. Positions, velocities and every other constraint stay as they were.
 * Checked as embra_body_create checks it; mass and density must be the body's own (its particles'
 * masses were set from them at creation). */
EMBRA_API embra_status embra_body_set_material(embra_world* world, embra_body_id body, const embra_material* material);
EMBRA_API embra_status embra_body_get_material(const embra_world* world, embra_body_id body,
                                               embra_material* out_material);
/* The masses (kg) of the body's particles, from the next step on, without a rebuild: masses[k] is
 * particle first + k's (embra_body_get_particles), and count must be the body's particle count.
 * Each mass is 0 or in [EMBRA_MIN_POSITIVE, EMBRA_MAX_ABS_VALUE]: 0 makes the particle immovable,
 * as a 0 in embra_body_def.masses does (it stays where it is, automatic tethers attach to it); a
 * positive mass makes an immovable particle free again. A hard-pinned particle keeps following its
 * pin, its new mass applying once the pin is destroyed; a soft pin, gravity, loads, fields and
 * every constraint act on the new mass (a heavier particle hangs lower on a compliant link).
 * Positions and velocities stay as they were. The body's material (its mass and density) is not
 * changed: it records how the creation masses were computed. Saved by embra_world_save_json as
 * the body's mesh masses, so a saved and reloaded world steps the same. Refused, changing nothing,
 * for a NULL masses, a count that is not the body's, or any mass negative, non-finite or in
 * (0, EMBRA_MIN_POSITIVE). */
EMBRA_API embra_status embra_body_set_masses(embra_world* world, embra_body_id body, const double* masses,
                                             int32_t count);
/* The masses (kg) of the body's particles as embra_body_set_masses takes them (0 = immovable), one
 * per particle, whether given at creation, computed from the material or set since. Two-call
 * pattern: out NULL and capacity 0 only write *out_count; capacity in doubles; too small a buffer
 * is EMBRA_ERROR_BUFFER_TOO_SMALL, nothing written. */
EMBRA_API embra_status embra_body_get_masses(const embra_world* world, embra_body_id body, double* out,
                                             int32_t capacity, int32_t* out_count);

/* ---------------------------------------------------------------------------------------------
 * Constraints, one at a time or in bulk
 * ------------------------------------------------------------------------------------------- */

typedef int32_t embra_constraint_kind;
enum {
  EMBRA_CONSTRAINT_DISTANCE = 0,     /* 2 particles: |x0 - x1| = rest (m). Stretch */
  EMBRA_CONSTRAINT_EDGE_ANGLE = 1,   /* 3 particles: angle at x0 between x1 - x0 and x2 - x0 = rest
                                        (rad, [0, pi]). Shear */
  EMBRA_CONSTRAINT_DIHEDRAL = 2,     /* 4 particles: angle between triangles (x0,x1,x2) and (x1,x0,x3)
                                        across edge x0-x1 = rest (rad, (-pi, pi]; 0 = flat). Bend */
  EMBRA_CONSTRAINT_TET_VOLUME = 3,   /* 4 particles: signed volume (x1-x0).((x2-x0)x(x3-x0))/6 = rest */
  EMBRA_CONSTRAINT_WELD = 4,         /* 2 particles: x0 = x1 (rest must be 0) */
  EMBRA_CONSTRAINT_TETHER = 5,       /* 2 particles: |x0 - x1| <= rest (m). A long-range attachment:
                                        pulls only when overstretched */
  EMBRA_CONSTRAINT_PLANARITY = 6,    /* 4 particles, a quad x0 x1 x2 x3 in order round it: signed
                                        distance between its diagonals x0-x2 and x1-x3 = rest (m; 0 =
                                        planar). (x1 - x0) . n / |n|, n = (x2 - x0) x (x3 - x1) */
  EMBRA_CONSTRAINT_PLANE_OFFSET = 7, /* 4 particles: signed distance of x0 from the plane through
                                        x1, x2, x3 = rest (m; positive on the side of the normal
                                        (x2 - x1) x (x3 - x1)). x0 may slide along the plane */
  EMBRA_CONSTRAINT_EQUAL_LENGTH = 8, /* 4 particles, two edges x0-x1 and x2-x3: |x0 - x1| - |x2 - x3|
                                        = rest (m; 0 = equal). The edges may share a particle (x1 =
                                        x2); an edge may not join a particle to itself. A set of
                                        edges held equal (gridshells): pair each with the next */
  EMBRA_CONSTRAINT_CONICAL = 9,      /* 5 particles, a vertex x0 of valence four and its neighbours
                                        x1 x2 x3 x4 in order round it: a12 - a23 + a34 - a41 = rest
                                        (rad, [-2 pi, 2 pi]; 0 = conical), a_ij the angle at x0
                                        between x_i - x0 and x_j - x0. With every face planar
                                        (EMBRA_CONSTRAINT_PLANARITY), a mesh conical at its inner
                                        vertices has exact face offsets: embra_panel_mesh_create
                                        builds it panels of constant thickness with planar joints.
                                        Added with embra_constraints_add (embra_constraint_def
                                        holds four particles) */
  EMBRA_CONSTRAINT_LENGTH_MIN = 10,  /* 2 particles: |x0 - x1| >= rest (m, >= 0). Unilateral: pushes
                                        only when shorter (a tether only pulls). A length range min
                                        <= |x0 - x1| <= max is a length_min of rest min and a tether
                                        of rest max on the same two particles. Coincident particles
                                        have no direction to be pushed apart in: not moved */
  EMBRA_CONSTRAINT_ANGLE_MIN = 11,   /* 3 particles: angle at x0 between x1 - x0 and x2 - x0 >= rest
                                        (rad, [0, pi]). Unilateral: opens the corner only */
  EMBRA_CONSTRAINT_ANGLE_MAX = 12,   /* 3 particles: the same angle <= rest (rad, [0, pi]).
                                        Unilateral: closes only. An angle range is an angle_min and an
                                        angle_max on the same corner */
  EMBRA_CONSTRAINT_COLINEAR = 13,    /* 3 particles: distance of x1 from the line through x0 and x2
                                        = rest (m, >= 0; 0 = the three on one line, x1 anywhere along
                                        it). |(x1 - x0) x (x2 - x0)| / |x2 - x0|. A point set on one
                                        line: each point with the set's two ends */
  EMBRA_CONSTRAINT_DIRECTION = 14,   /* 4 particles: angle between the edges x0 -> x1 and x2 -> x3 =
                                        rest (rad, [0, pi]; 0 = x0-x1 along x2-x3, pi = against it).
                                        The reference edge x2-x3 is a fixed direction when both are
                                        immovable (mass 0 or hard-pinned); movable, the two edges turn
                                        toward each other (parallel edges). The edges may share a
                                        particle (x1 = x2); an edge may not join a particle to itself */
  EMBRA_CONSTRAINT_COCIRCULAR = 15,  /* 4 particles, a convex quad x0 x1 x2 x3 in order round it:
                                        a0 - a1 + a2 - a3 = rest (rad, [-2 pi, 2 pi]; 0 = cyclic), a_k
                                        the angle at x_k between its two neighbours. A planar quad
                                        with opposite angles summing to pi has its corners on one
                                        circle; planarity is a separate constraint
                                        (EMBRA_CONSTRAINT_PLANARITY on the same quad) */
  EMBRA_CONSTRAINT_COSPHERICAL = 16  /* 5 particles: signed distance of x4 from the sphere through
                                        x0 x1 x2 x3 = rest (m; 0 = the five on one sphere, positive
                                        outside). x0..x3 must not be flat. Added with
                                        embra_constraints_add (embra_constraint_def holds four
                                        particles). A point set on one sphere: four well-spread
                                        points of it with each of the others */
};
/* Number of particles one constraint of `kind` takes, or 0 for an unknown kind. */
EMBRA_API int32_t embra_constraint_arity(embra_constraint_kind kind);

#define EMBRA_CONSTRAINT_DEF_VERSION 1
typedef struct embra_constraint_def {
  int32_t version; /* EMBRA_CONSTRAINT_DEF_VERSION */
  embra_constraint_kind kind;
  embra_group_id group;      /* {0,0} = default group */
  int32_t particles[4];      /* the first embra_constraint_arity(kind) are used: a kind of more
                                (CONICAL, COSPHERICAL) is added with embra_constraints_add */
  int32_t rest_from_current; /* 1 (default): measure rest from current positions; 0: use rest */
  int32_t reserved0;
  double rest;       /* rest value in the kind's unit, when rest_from_current is 0 */
  double compliance; /* >= 0, kind's unit per newton; 0 = hard (default) */
} embra_constraint_def;

EMBRA_API embra_constraint_def embra_default_constraint_def(void);
EMBRA_API embra_status embra_constraint_add(embra_world* world, const embra_constraint_def* def);

#define EMBRA_CONSTRAINT_BATCH_DEF_VERSION 1
typedef struct embra_constraint_batch_def {
  int32_t version; /* EMBRA_CONSTRAINT_BATCH_DEF_VERSION */
  embra_constraint_kind kind;
  embra_group_id group; /* {0,0} = default group */
  int32_t count;        /* number of constraints, > 0 */
  int32_t reserved0;
  const int32_t* particles;  /* int32_t[count * arity], required */
  const double* rest;        /* double[count], or NULL to measure each from current positions */
  const double* compliances; /* double[count], or NULL to use `compliance` for all */
  double compliance;         /* >= 0; default 0 (hard) */
} embra_constraint_batch_def;

EMBRA_API embra_constraint_batch_def embra_default_constraint_batch_def(void);
/* Adds all constraints of the batch or none. */
EMBRA_API embra_status embra_constraints_add(embra_world* world, const embra_constraint_batch_def* def);

/* Planarity of a polygon of any number of corners: `particles`, `count` >= 4 corners in order
 * round it, held in one plane by EMBRA_CONSTRAINT_PLANARITY constraints of rest 0 on windows of four
 * consecutive corners: the quad itself for count 4, and for more all `count` windows (c_i,
 * c_i+1, c_i+2, c_i+3), indices round the polygon, so that every corner is in four windows and none
 * defines the plane. Consecutive windows share three corners, so all of them planar is the polygon
 * planar. In `group` ({0,0} = default), with `compliance` (m/N, >= 0; 0 = hard). *out_added (may be
 * NULL) is the number added, the last of the group's planarity constraints. All or none: refused for
 * a corner outside the world or given twice, and for a window whose diagonals are parallel (four
 * corners in line: no plane to pull them to). */
EMBRA_API embra_status embra_polygon_planarity_add(embra_world* world, embra_group_id group, const int32_t* particles,
                                                   int32_t count, double compliance, int32_t* out_added);

/* A rigid point set by bracing (not shape matching): `particles`, `count` >= 3 points, keep their
 * current shape, moving only as one rigid body, through constraints of existing kinds with rests
 * measured now. A base of three or four of the points (the first, the one farthest from it, the one
 * farthest from their line, the one farthest from their plane) is braced by the distances among
 * its points, and every other point by its distances to each base point. A solid set (a point at
 * least 1e-3 of the set's size off the plane of the first three base points) adds the base
 * tetrahedron's volume (EMBRA_CONSTRAINT_TET_VOLUME: keeps its handedness, which distances alone
 * cannot); a flat one holds each other point at its offset from the base's plane
 * (EMBRA_CONSTRAINT_PLANE_OFFSET). Either way n points take 4 n - 9 constraints; *out_added (may
 * be NULL) is that count. In `group` ({0,0} = default), with `compliance` (>= 0; 0 = hard). All or
 * none: refused for a point outside the world or given twice, two points at one place, and a set on
 * one line (no frame to hold). */
EMBRA_API embra_status embra_rigid_set_add(embra_world* world, embra_group_id group, const int32_t* particles,
                                           int32_t count, double compliance, int32_t* out_added);

/* Shape matching (Kangaroo2's RigidPointSet, ShapeOp's Rigid goal, Vellum's Shape Match): the
 * points `particles`, `count` >= 3, pulled every projection toward the best-fit rigid placement of
 * their rest shape, their positions now. The fit: with the particles' masses m_i (an immovable
 * particle counts as the heaviest of the others), the mass-weighted centroids c of the points x_i
 * and r_c of the rest points r_i, and A = sum m_i (x_i - c)(r_i - r_c)^T, R is the proper rotation
 * (det +1) nearest to A (its polar factor, from a 3x3 Jacobi SVD); the goals are g_i = c + R (r_i -
 * r_c). Each projection makes the fit once and moves each point, the goals held fixed, by the XPBD
 * step of C_i = x_i - g_i with compliance `compliance` m_bar / m_i (m/N; m_bar the mean of the
 * m_i): the set's energy is E = 1 / (2 compliance) sum (m_i / m_bar) |x_i - g_i|^2 (J), whose
 * gradient is (m_i / (m_bar compliance)) (x_i - g_i). 0 = hard: one projection puts every movable
 * point on its goal, so a free set moves as one rigid body (the projection moves no centre of mass
 * and has no net torque about it, to rounding); a compliant set gives way under load in proportion
 * to `compliance`, each point as a soft pin of that compliance would for equal masses. Hard-pinned
 * and immovable points take part in the fit but are not moved. Projected in `group` ({0,0} =
 * default) after its constraints, one set at a time in the order added (the same bits at any thread
 * count); not part of the global solve's Newton system (embra_solver_def.global_solve: the
 * iterations after it project it) nor of the residual reports. *out_index (may be NULL) is its
 * index among the group's shape matches. All or none: refused for NULL particles, count < 3, a
 * particle outside the world or given twice, a compliance negative or not finite, a stale group,
 * and rest points all at one place or on one line (within 1e-6 of their reach: no rotation about
 * that line to fit). Saved in scenes ("shape_matches"); destroying the group removes them. Which to
 * use: embra_rigid_set_add braces a set with 4 n - 9 constraints of existing kinds (forces per
 * member, the global solve, the residual reports); a shape match is one goal of n points, cheaper
 * for large sets, exactly rigid in one projection when hard, and soft with one compliance. */
EMBRA_API embra_status embra_shape_match_add(embra_world* world, embra_group_id group, const int32_t* particles,
                                             int32_t count, double compliance, int32_t* out_index);
/* Removes shape match `index` of `group` ({0,0} = default); those after it move down by one. */
EMBRA_API embra_status embra_shape_match_remove(embra_world* world, embra_group_id group, int32_t index);
/* The number of shape matches `group` ({0,0} = default) holds. */
EMBRA_API embra_status embra_group_get_shape_match_count(const embra_world* world, embra_group_id group,
                                                         int32_t* out_count);

/* Edits without a rebuild. A constraint is named by its group ({0,0}: the default group), kind and
 * index among the group's constraints of that kind: those bodies generated first (in body order),
 * then the added ones in the order added, the numbering of embra_constraint_residual.index and
 * embra_group_get_residuals. Each edit changes that constraint only, from the next step on;
 * positions, velocities and every other constraint stay as they were. Only added constraints are
 * edited one at a time: those a body generated follow its material (embra_body_set_material), and
 * an edit naming one is refused. A body created later puts its generated constraints before the
 * added ones of its groups, so their indices grow by that many. */

/* How many constraints of `kind` the group holds (*out_count), and how many of those bodies
 * generated (*out_generated, may be NULL): the added ones are [*out_generated, *out_count). */
EMBRA_API embra_status embra_group_get_constraint_count(const embra_world* world, embra_group_id group,
                                                        embra_constraint_kind kind, int32_t* out_count,
                                                        int32_t* out_generated);
/* One constraint as embra_constraint_add would take it: kind, group, particles (-1 past the arity),
 * rest (before any body's rest scale) with rest_from_current 0, and compliance. Refused for a kind of
 * more particles than the def holds (CONICAL, COSPHERICAL: embra_world_save_json lists them). */
EMBRA_API embra_status embra_constraint_get(const embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                            int32_t index, embra_constraint_def* out_def);
/* Compliance >= 0 and finite, in the kind's unit per newton. */
EMBRA_API embra_status embra_constraint_set_compliance(embra_world* world, embra_group_id group,
                                                       embra_constraint_kind kind, int32_t index, double compliance);
/* Rest value in the kind's unit, checked as embra_constraint_add checks it (a distance >= 0, an
 * angle in its range, a weld 0). */
EMBRA_API embra_status embra_constraint_set_rest(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                                 int32_t index, double rest);
/* Moves the constraint to the end of group `to`'s constraints of its kind; *out_new_index (may be NULL)
 * receives its index there. The constraints after it in `group` move down by one. Not into the
 * contact group. */
EMBRA_API embra_status embra_constraint_set_group(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                                  int32_t index, embra_group_id to, int32_t* out_new_index);
/* Removes the constraint; the constraints after it in its group move down by one. */
EMBRA_API embra_status embra_constraint_remove(embra_world* world, embra_group_id group, embra_constraint_kind kind,
                                               int32_t index);

/* Plasticity and rupture of an added EMBRA_CONSTRAINT_DISTANCE or EMBRA_CONSTRAINT_DIHEDRAL (a
 * hinge), named as for the edits above, checked after every step at the step's end positions.
 * Its strain: (length - rest) / rest for a distance (dimensionless), angle - rest for a dihedral
 * (rad, wrapped to (-pi, pi]). Past `yield` (> 0) the rest follows the constraint so that the strain
 * is `yield` again (perfect plasticity: unloaded, it keeps the permanent set, its loaded value less
 * the elastic part); past `rupture` (> 0) the constraint is removed (the ones after it in its group
 * move down by one) and reported by embra_world_get_broken. 0 turns either off; the defaults are 0
 * (elastic, unbreakable). Each finite and >= 0; refused for other kinds, generated constraints and
 * a distance of rest 0 (no strain); while either is set, embra_constraint_set_rest refuses a rest of
 * 0 for that distance. */
EMBRA_API embra_status embra_constraint_set_plasticity(embra_world* world, embra_group_id group,
                                                       embra_constraint_kind kind, int32_t index, double yield,
                                                       double rupture);
/* The constraint's yield and rupture strains (0: none). Both outputs required. */
EMBRA_API embra_status embra_constraint_get_plasticity(const embra_world* world, embra_group_id group,
                                                       embra_constraint_kind kind, int32_t index, double* out_yield,
                                                       double* out_rupture);

/* A constraint that broke past its rupture strain, named as it was when it broke. */
typedef struct embra_broken_constraint {
  embra_group_id group; /* its group (the default group by its own id, not {0,0}) */
  int32_t kind;         /* EMBRA_CONSTRAINT_DISTANCE or EMBRA_CONSTRAINT_DIHEDRAL */
  int32_t index;        /* its index among the group's constraints of that kind when it broke */
  int32_t particles[4]; /* its particles, -1 past its arity */
  int64_t frame;        /* the frame whose step broke it (embra_step_report.frame after that step) */
  double strain;        /* the strain it broke at (dimensionless, or rad for a dihedral) */
} embra_broken_constraint;

/* The constraints broken since the last read, in the order they broke. Two-call pattern: out NULL
 * and capacity 0 only write *out_count (required), and the list is kept; a buffer of at least that
 * capacity receives them and the list is emptied (the next read returns only later breaks); a
 * smaller one is EMBRA_ERROR_BUFFER_TOO_SMALL, nothing written, the list kept. Not saved with a
 * scene. */
EMBRA_API embra_status embra_world_get_broken(embra_world* world, embra_broken_constraint* out, int32_t capacity,
                                              int32_t* out_count);

/* ---------------------------------------------------------------------------------------------
 * Pins: a particle held at a target the host moves between steps (dragging, raising a tent)
 * ------------------------------------------------------------------------------------------- */

#define EMBRA_PIN_DEF_VERSION 1
typedef struct embra_pin_def {
  int32_t version;      /* EMBRA_PIN_DEF_VERSION */
  int32_t particle;     /* world particle index */
  double target[3];     /* m */
  double compliance;    /* 0 (default) = hard: the particle follows the target exactly, gliding
                           there over the substeps of the next frame; > 0 (m/N): a spring-like
                           soft pin in `group` */
  embra_group_id group; /* group of a soft pin; {0,0} = default group */
} embra_pin_def;

EMBRA_API embra_pin_def embra_default_pin_def(void);
/* A particle takes at most one hard pin. */
EMBRA_API embra_status embra_pin_create(embra_world* world, const embra_pin_def* def, embra_pin_id* out_pin);
/* Sliding supports: a pin that holds its particle on a plane or a line through the target, or on a
 * polyline, and lets it slide along it, frictionless; or a per-axis anchor (EMBRA_PIN_SUPPORT_AXES,
 * Kangaroo's AnchorXYZ, a roller) that holds chosen world coordinates of its particle at the
 * target's and leaves the others free ({0, 0, 1}: z held, x and y free). A support is a pin (an
 * embra_pin_id: embra_pin_destroy, embra_pin_set_target, embra_world_get_pins and the scene's
 * "pins" take it), projected in its group like a constraint, never kinematic; its reaction
 * (embra_world_get_reactions) is normal to the plane or across the line, and for an axes support
 * has only the held components (the free ones exactly 0). */
enum {
  EMBRA_PIN_SUPPORT_POINT = 0,    /* the particle held at the target: embra_pin_create's pin */
  EMBRA_PIN_SUPPORT_PLANE = 1,    /* on the plane through the target, normal `axis` */
  EMBRA_PIN_SUPPORT_LINE = 2,     /* on the line through the target, along `axis` */
  EMBRA_PIN_SUPPORT_POLYLINE = 3, /* on the closest point of a polyline, made by
                                    embra_polyline_support_create (below): inside a segment it
                                    slides along it and its reaction is normal to the segment; at
                                    a vertex it is held there until pulled along a segment. The
                                    closest point is searched over every segment at every
                                    projection (cost linear in the points) */
  EMBRA_PIN_SUPPORT_AXES = 4,     /* a per-axis anchor: the world coordinates whose `axis` component is
                                    1 held at the target's, those whose component is 0 free */
  EMBRA_PIN_SUPPORT_MESH = 5      /* on the closest point of a triangle mesh, made by
                                     embra_mesh_support_create (below): inside a triangle it slides in
                                     it and its reaction is normal to it; on an edge or at a vertex it is
                                     held there until pulled into a triangle. The closest point is
                                     searched over every triangle at every projection (cost linear in
                                     the triangles) */
};

#define EMBRA_SUPPORT_DEF_VERSION 1
typedef struct embra_support_def {
  int32_t version;  /* EMBRA_SUPPORT_DEF_VERSION */
  int32_t particle; /* world particle index */
  int32_t support;  /* EMBRA_PIN_SUPPORT_*; default EMBRA_PIN_SUPPORT_PLANE */
  int32_t reserved0;
  double target[3];     /* m: a point of the plane or line; where an axes support holds */
  double axis[3];       /* the plane's normal or the line's direction: finite, of any nonzero length
                           (kept as a unit vector); for EMBRA_PIN_SUPPORT_AXES the held coordinates:
                           each component 1 (held) or 0 (free), not all 0; default {0, 0, 1} */
  double compliance;    /* 0 (default) = hard (projected with compliance 0); > 0: m/N */
  embra_group_id group; /* its group; {0,0} = default group */
} embra_support_def;

EMBRA_API embra_support_def embra_default_support_def(void);
/* Creates a support (EMBRA_PIN_SUPPORT_POINT: a pin, as embra_pin_create). Refused: an unknown
 * support, a particle out of range, a non-finite target or axis, a zero axis for a plane or line
 * (or one too short to normalise), an axes support's axis with a component other than 0 or 1 or
 * with none 1, a negative or non-finite compliance, a stale group;
 * EMBRA_PIN_SUPPORT_POLYLINE (its curve comes through embra_polyline_support_create) and
 * EMBRA_PIN_SUPPORT_MESH (its mesh comes through embra_mesh_support_create). */
EMBRA_API embra_status embra_support_create(embra_world* world, const embra_support_def* def, embra_pin_id* out_pin);

/* A support on a polyline curve (EMBRA_PIN_SUPPORT_POLYLINE): a pin that holds its particle on the
 * closest point of the polyline through `points` (open, or closed back to its first point), the
 * points offsets from `target`, so embra_pin_set_target moves the curve as a host moves a collider.
 * Frictionless, hard or compliant, projected in its group like the other supports. */
#define EMBRA_POLYLINE_SUPPORT_DEF_VERSION 1
typedef struct embra_polyline_support_def {
  int32_t version;      /* EMBRA_POLYLINE_SUPPORT_DEF_VERSION */
  int32_t particle;     /* world particle index */
  double target[3];     /* m: the curve's origin; default {0, 0, 0} (the points are world points) */
  int32_t point_count;  /* [2, EMBRA_MAX_PARTICLES]; at least 3 when closed */
  int32_t closed;       /* 1: the last point joins the first; 0 (default): open */
  const double* points; /* double[3 * point_count], m, offsets from target (copied at creation); no
                           two consecutive points equal (nor the last and the first when closed) */
  double compliance;    /* 0 (default) = hard; > 0: m/N */
  embra_group_id group; /* its group; {0,0} = default group */
} embra_polyline_support_def;

EMBRA_API embra_polyline_support_def embra_default_polyline_support_def(void);
/* Creates a polyline support. Refused: a particle out of range, a point count out of range, NULL
 * points, a non-finite target or point, a degenerate (zero-length) segment, `closed` other than 0
 * or 1, a negative or non-finite compliance, a stale group. */
EMBRA_API embra_status embra_polyline_support_create(embra_world* world, const embra_polyline_support_def* def,
                                                     embra_pin_id* out_pin);
/* A polyline support's points as created: m, offsets from its target, point k at out_points[3 k ..
 * 3 k + 2]. embra_pin_set_target moves the target and so the whole curve, and leaves these offsets
 * as they are: the curve's world points are the target (embra_pin_get_target) plus these. Two-call
 * pattern: out_points NULL and capacity 0 only write *out_count; a smaller capacity is
 * EMBRA_ERROR_BUFFER_TOO_SMALL, nothing written. Capacity in points. Refused: a stale pin, a pin that
 * is not a polyline support. */
EMBRA_API embra_status embra_polyline_support_get_points(const embra_world* world, embra_pin_id pin, double* out_points,
                                                         int32_t capacity, int32_t* out_count);
/* A support on a triangle mesh (EMBRA_PIN_SUPPORT_MESH, Kangaroo's OnMesh): a pin that holds its
 * particle on the closest point of the mesh, whose vertices are offsets from `target`, so
 * embra_pin_set_target moves the mesh as a host moves a collider. Frictionless, hard or compliant,
 * projected in its group like the other supports; its reaction (embra_world_get_reactions) is
 * normal to the triangle it slides in. */
#define EMBRA_MESH_SUPPORT_DEF_VERSION 1
typedef struct embra_mesh_support_def {
  int32_t version;          /* EMBRA_MESH_SUPPORT_DEF_VERSION */
  int32_t particle;         /* world particle index */
  double target[3];         /* m: the mesh's origin; default {0, 0, 0} (the vertices are world points) */
  int32_t vertex_count;     /* [3, EMBRA_MAX_PARTICLES] */
  int32_t triangle_count;   /* [1, EMBRA_MAX_CONSTRAINTS] */
  const double* vertices;   /* double[3 * vertex_count], m, offsets from target (copied at creation) */
  const int32_t* triangles; /* int32_t[3 * triangle_count], 0-based vertex indices (copied); each
                               triangle of nonzero area. Open or closed, any orientation */
  double compliance;        /* 0 (default) = hard; > 0: m/N */
  embra_group_id group;     /* its group; {0,0} = default group */
} embra_mesh_support_def;

EMBRA_API embra_mesh_support_def embra_default_mesh_support_def(void);
/* Creates a mesh support. Refused: a particle out of range, a vertex or triangle count out of range,
 * NULL vertices or triangles, a non-finite target or vertex, a vertex index out of range, a
 * degenerate (zero-area) triangle, a negative or non-finite compliance, a stale group. */
EMBRA_API embra_status embra_mesh_support_create(embra_world* world, const embra_mesh_support_def* def,
                                                 embra_pin_id* out_pin);
/* Destroys a pin (and a scene action that moves it). */
EMBRA_API embra_status embra_pin_destroy(embra_world* world, embra_pin_id pin);
/* Moves the target (m); a hard-pinned particle travels there over the next step's substeps. The
 * host takes over: a scene's path for this pin stops (a dragged pin is not pulled back). */
EMBRA_API embra_status embra_pin_set_target(embra_world* world, embra_pin_id pin, const double target[3]);
EMBRA_API embra_status embra_pin_get_target(const embra_world* world, embra_pin_id pin, double out_target[3]);
/* The particle a pin holds. */
EMBRA_API embra_status embra_pin_get_particle(const embra_world* world, embra_pin_id pin, int32_t* out_particle);

/* ---------------------------------------------------------------------------------------------
 * Colliders: rigid shapes the host places and moves between steps
 * ------------------------------------------------------------------------------------------- */

typedef int32_t embra_collider_shape;
enum {
  EMBRA_COLLIDER_PLANE = 0,   /* the half-space below the plane through `position` with normal
                                 rotation * (0, 0, 1); particles stay above */
  EMBRA_COLLIDER_SPHERE = 1,  /* solid sphere of `radius` centred at `position` */
  EMBRA_COLLIDER_BOX = 2,     /* solid box of `half_extents` along its local x, y, z */
  EMBRA_COLLIDER_CAPSULE = 3, /* points within `radius` of the segment from local (0, 0, -half_length)
                                 to (0, 0, half_length) */
  EMBRA_COLLIDER_CONVEX = 4,  /* solid convex hull of `vertex_count` local points (at least 4, not all
                                 in one plane) */
  EMBRA_COLLIDER_MESH = 5     /* triangle mesh of local `vertices` and `triangles`. Closed (every edge
                                 shared by exactly two triangles, wound consistently): a solid,
                                 particles stay outside. Open: a two-sided sheet, particles stay on
                                 the side they come from. */
};

/* Every shape moves with the pose the host sets (embra_collider_set_transform); contacts are found
 * along each particle's path over each substep, against the collider's motion over that substep,
 * so no speed carries a particle through a thin or moving collider. Geometry arrays are copied at
 * creation; they are not read afterwards. */
#define EMBRA_COLLIDER_DEF_VERSION 2
typedef struct embra_collider_def {
  int32_t version; /* EMBRA_COLLIDER_DEF_VERSION */
  embra_collider_shape shape;
  double position[3];      /* m */
  double rotation[4];      /* unit quaternion {w, x, y, z}; default identity {1, 0, 0, 0} */
  double radius;           /* m, sphere and capsule, > 0; default 1 */
  double thickness;        /* m, extra clearance; default 0 */
  double friction_static;  /* default 0.5 */
  double friction_dynamic; /* default 0.3 */
  /* Fields added in version 2. */
  double half_extents[3];   /* m, box only, each > 0; default {0.5, 0.5, 0.5} */
  double half_length;       /* m, capsule only, >= 0 (0 = a sphere); default 0.5 */
  int32_t vertex_count;     /* convex (>= 4) and mesh (>= 3) only; default 0 */
  int32_t triangle_count;   /* mesh only, > 0; default 0 */
  const double* vertices;   /* m, 3 per vertex, local frame; convex and mesh only; default NULL */
  const int32_t* triangles; /* mesh only: 3 vertex indices (0-based) per triangle, counter-clockwise
                               seen from outside for a closed mesh (one wound all inward is turned);
                               none may have zero area; default NULL */
} embra_collider_def;

EMBRA_API embra_collider_def embra_default_collider_def(void);
EMBRA_API embra_status embra_collider_create(embra_world* world, const embra_collider_def* def,
                                             embra_collider_id* out_collider);
/* Destroys a collider (and a scene action that moves it). */
EMBRA_API embra_status embra_collider_destroy(embra_world* world, embra_collider_id collider);
/* Sets where the collider is at the end of the next step; it moves there along a straight path
 * over the substeps, and particles it drags take its velocity through friction. The host takes
 * over: a scene's path for this collider stops. */
EMBRA_API embra_status embra_collider_set_transform(embra_world* world, embra_collider_id collider,
                                                    const double position[3], const double rotation[4]);
/* Where the collider is now: the pose it reached at the end of the last step (before any step, or
 * after embra_collider_set_transform, the pose it will reach at the end of the next one). The
 * rotation is a unit quaternion {w, x, y, z}. Scene actions that move a collider show here. */
EMBRA_API embra_status embra_collider_get_transform(const embra_world* world, embra_collider_id collider,
                                                    double out_position[3], double out_rotation[4]);

/* ---------------------------------------------------------------------------------------------
 * Stepping and reading back
 * ------------------------------------------------------------------------------------------- */

/* Advances one frame (solver dt). A frame that does not complete leaves the world exactly as
 * before the call, the scene actions applied for that frame included: EMBRA_ERROR_NUMERICAL when
 * the state went non-finite or beyond EMBRA_MAX_ABS_VALUE (embra_world_get_warning says where; a
 * hard pin's target 1e300 away reached in one frame is such a state), EMBRA_ERROR_CANCELLED when
 * embra_world_cancel stopped it. */
EMBRA_API embra_status embra_world_step(embra_world* world);
/* Asks the step in progress on another thread to stop: it checks between iterations, restores the
 * world and returns EMBRA_ERROR_CANCELLED. The only call that may overlap another call on the same
 * world (from any thread). A request is consumed by the step it stops; one made while no step
 * runs stops the next step before its first iteration. */
EMBRA_API embra_status embra_world_cancel(embra_world* world);

typedef struct embra_step_report {
  int64_t frame;         /* frames stepped since the world was created */
  double time;           /* simulated s */
  double kinetic_energy; /* J */
  double max_speed;      /* m/s, over all particles */
  double residual_max;   /* max |C + compliance/h^2 * lambda| over all constraints (in each
                            constraint's unit: m, rad, m^3); contacts: penetration depth */
  double residual_rms;
  int64_t constraint_count; /* constraints measured, including soft pins and contacts */
  int64_t contact_count;    /* particle-collider contacts in the last substep */
  int32_t settled;          /* 1 when max_speed <= settle_speed */
  int32_t reserved0;
} embra_step_report;

/* The report of the last step (all zero before the first). */
EMBRA_API embra_status embra_world_get_report(const embra_world* world, embra_step_report* out_report);

/* Residuals by kind, each in its own unit (embra_residual_unit): the step report's residual_max
 * takes the largest over every constraint whatever its unit (m, rad, m^3); these say which. */
enum {
  EMBRA_RESIDUAL_PINS = -1,    /* pins, soft and hard: distance from the target (m) */
  EMBRA_RESIDUAL_CONTACTS = -2 /* collider and panel-face contacts: penetration (m) */
};

typedef struct embra_kind_residual {
  int32_t kind; /* EMBRA_CONSTRAINT_*, EMBRA_RESIDUAL_PINS or EMBRA_RESIDUAL_CONTACTS */
  int32_t reserved0;
  int64_t count; /* constraints of the kind measured (a weld counts once: |x0 - x1|) */
  double max;    /* max |C + compliance/h^2 * lambda| over them, in the kind's unit */
  double rms;
} embra_kind_residual;

/* The unit of a kind's values and residuals ("m", "rad", "m^3"; "m" for EMBRA_RESIDUAL_PINS and
 * _CONTACTS), or NULL for a number that is neither. A static string. */
EMBRA_API const char* embra_residual_unit(int32_t kind);
/* Its name: the constraint kind's scene name ("distance", "dihedral", ...), "pins" or "contacts";
 * NULL for a number that is neither. A static string. */
EMBRA_API const char* embra_residual_name(int32_t kind);
/* The last step's residuals by kind, for every kind the world holds (count > 0): the constraint kinds
 * in number order, then pins, then contacts. *out_count (required) receives how many; out NULL and
 * capacity 0 only ask for it; a smaller capacity is EMBRA_ERROR_BUFFER_TOO_SMALL. */
EMBRA_API embra_status embra_world_get_residuals(const embra_world* world, embra_kind_residual* out, int32_t capacity,
                                                 int32_t* out_count);

/* Which constraints are fighting (after a step). A constraint's force is its multiplier of the last
 * substep over h^2, in the unit conjugate to its value: N for a length, N m for an angle, N/m^2 for a
 * volume; its violation |C| (how far from its rest) times its force is then an energy (J) for every
 * kind, the scale on which the worst are ranked (the residual breaking ties). A compliant constraint
 * that has converged has a residual near 0 however far it is stretched: the violation shows it. */
typedef struct embra_constraint_residual {
  int32_t kind;         /* EMBRA_CONSTRAINT_*, or EMBRA_RESIDUAL_PINS for a soft pin */
  int32_t index;        /* in its group's constraints of that kind, in the order they were added
                           (embra_group_get_residuals); -1 for a pin */
  embra_group_id group; /* its group */
  embra_pin_id pin;     /* the soft pin; {0, 0} otherwise */
  int32_t particles[4]; /* its particles (the first four of a conical vertex's five: the vertex and
                           its first three neighbours); -1 past the kind's arity */
  double residual;      /* |C + compliance/h^2 * lambda| in the kind's unit (embra_residual_unit) */
  double violation;     /* |C|, in the same unit (a one-sided kind, e.g. a tether: how far on its
                           wrong side, for a tether how far overstretched) */
  double force;         /* |lambda| / h^2 */
} embra_constraint_residual;

/* The `capacity` worst constraints and soft pins of the last step, worst first; *out_count
 * (required) receives how many were written (fewer when the world holds fewer). */
EMBRA_API embra_status embra_world_get_worst_constraints(const embra_world* world, embra_constraint_residual* out,
                                                         int32_t capacity, int32_t* out_count);

typedef struct embra_group_conflict {
  embra_group_id a, b; /* a before b in the projection order */
  double force;        /* N: over their shared movable particles, the smaller of the two groups' forces on
                          each times how far they point against each other (-cos of the angle, where
                          negative): two groups pulling a particle straight apart add the smaller pull */
  int64_t particles;   /* particles where the two forces point more than 120 degrees apart */
} embra_group_conflict;

/* Every pair of groups pulling against each other in the last step, largest force first (two-call
 * pattern: out NULL and capacity 0 ask for the count; a smaller capacity is BUFFER_TOO_SMALL). */
EMBRA_API embra_status embra_world_get_group_conflicts(const embra_world* world, embra_group_conflict* out,
                                                       int32_t capacity, int32_t* out_count);

/* The residual of every constraint of `kind` in `group` after the last step, in the order they were
 * added to the group, in the kind's unit: for colouring a mesh by what fights. Constraints added
 * since the last step read 0. Two-call pattern (out NULL, capacity 0: *out_count only). */
EMBRA_API embra_status embra_group_get_residuals(const embra_world* world, embra_group_id group, int32_t kind,
                                                 double* out, int64_t capacity, int64_t* out_count);

/* ---------------------------------------------------------------------------------------------
 * Statics: member forces and support reactions after a step
 *
 * From the last substep's multipliers: a constraint's projection moves its particles as a force
 * lambda / h^2 grad C would over a substep (h = dt / substeps). At a static rest (the world settled,
 * every substep ending where it began) these forces balance each free particle's weight and point
 * load: exactly (to rounding) with realign_passes >= 1, which evaluates them at the substep's end;
 * textbook XPBD (realign_passes 0) leaves an imbalance of the order of h^2 g / member length of the
 * forces. Read them after embra_world_step or embra_world_solve; constraints added since read 0.
 * A saved scene keeps them (its state.forces: the last substep's multipliers and contact forces,
 * docs/scene-format.md): a world loaded from a scene saved after a step (embra_world_save_json or
 * _file, `embra run`'s final.json) reads the same forces and reactions, bit for bit, before its first
 * step; a scene without them reads 0 until a step. Stepping does not read them (every substep starts
 * its multipliers at 0), so a loaded world steps on the same either way.
 * A hard pin's reaction is read from what its particle took, not from the end of the substep: each
 * projection of a constraint holding it hands it grad C dlambda (the gradient where the projection
 * starts), summed over the last substep. Whatever the constraints' multipliers (redundant hard
 * constraints, as a panel mesh's, let them grow against each other), the pins then carry exactly
 * what the free particles do not: at a static rest the reactions sum to minus the load to rounding,
 * with or without realignment passes.
 * ------------------------------------------------------------------------------------------- */

/* The force of every constraint of `kind` in `group`, -lambda / h^2 of the last substep, in the order
 * they were added: a distance or tether's tension (N, positive when it pulls its ends together, negative
 * in compression); an equal_length's tension added to its edge x0-x1 (N; the same compression added to
 * x2-x3); for the other kinds the generalised force conjugate to the value (N m for an angle, N/m^2
 * for a volume), positive when it pulls the value down. Refused for EMBRA_CONSTRAINT_WELD (three
 * multipliers) and a number that is no kind. Two-call pattern (out NULL, capacity 0: *out_count
 * only; a smaller capacity is EMBRA_ERROR_BUFFER_TOO_SMALL). */
EMBRA_API embra_status embra_group_get_forces(const embra_world* world, embra_group_id group, int32_t kind, double* out,
                                              int64_t capacity, int64_t* out_count);

typedef struct embra_reaction {
  embra_pin_id pin;
  int32_t particle; /* the pinned particle */
  int32_t reserved0;
  double force[3]; /* N: the force the pin exerts on its particle. A soft pin or a sliding support
                      (normal to its plane, across its line): its multiplier over
                      h^2. A hard point pin: minus the particle's weight (gravity / inverse mass; none
                      for an immovable particle), its point load, its share of the area and line
                      loads (at the current positions) and the impulse over h^2 the constraints
                      handed it in the last substep (every constraint kind and weld, shape
                      matches, and the automatic tethers when realign_passes >= 1: without
                      realignment they keep no multiplier; the global solve's steps without
                      realignment: read from the multipliers where the substep ends). Fields
                      (wind, pressure, surface tension, vortex), self contacts and contacts on the
                      pinned particle are not counted */
} embra_reaction;

/* The reaction at every live pin after the last step, pins in creation-slot order (as
 * embra_world_get_pins). At a static rest the reactions sum to minus the total applied load (every
 * particle's weight and point load, and every area and line load; loads on an immovable particle
 * that no pin holds go to no reaction). Two-call pattern (out NULL, capacity 0: *out_count only). */
EMBRA_API embra_status embra_world_get_reactions(const embra_world* world, embra_reaction* out, int32_t capacity,
                                                 int32_t* out_count);

typedef struct embra_collider_reaction {
  embra_collider_id collider;
  int64_t contacts; /* its contacts that exerted a force in the last substep */
  double force[3];  /* N: the force the collider exerts on the particles, summed over its contacts
                       of the last substep: a particle contact's multiplier (a length) times the
                       particle's mass over h^2, a panel face contact's (against a sphere) over h^2,
                       along the contact normal where the solve left the particles; plus friction
                       and the push back onto the surface after the solve (the displacement each
                       gave, times the mass over h^2) */
  double moment[3]; /* N m: the moment of those forces about the collider's position, each acting
                       at its particle's position after the step (a face contact: at the point of
                       its triangle nearest the sphere's centre) */
} embra_collider_reaction;

/* The force every live collider exerts on the world after the last step, colliders in
 * creation-slot order (as embra_world_get_colliders); a collider without contacts reads 0. At a
 * static rest the pins' reactions (embra_world_get_reactions) and the colliders' sum to minus the
 * total applied load. A contact on a hard-pinned particle is not counted (its pin's reaction holds
 * what the contact does not). Two-call pattern (out NULL, capacity 0: *out_count only; a smaller
 * capacity is EMBRA_ERROR_BUFFER_TOO_SMALL and writes nothing). */
EMBRA_API embra_status embra_world_get_collider_reactions(const embra_world* world, embra_collider_reaction* out,
                                                          int32_t capacity, int32_t* out_count);

typedef struct embra_group_report {
  int64_t count;       /* constraints in the group (soft pins and contacts included) */
  double residual_max; /* as in embra_step_report, over this group */
  double residual_rms;
} embra_group_report;

EMBRA_API embra_status embra_group_get_report(const embra_world* world, embra_group_id group,
                                              embra_group_report* out_report);

/* ---------------------------------------------------------------------------------------------
 * Solve to tolerance: step until done, and say why it stopped
 *
 * embra_world_solve steps frames (scene actions applied, as embra_world_step) until the world is at
 * rest for hold_frames frames in a row (max_speed <= settle_speed) and, with
 * EMBRA_SOLVE_UNTIL_TOLERANCE, every panel mesh's planarity (both layers), corner distance,
 * thickness and miter are at or below the world's tolerance targets and every kind's largest
 * constraint residual of the last step (embra_world_get_residuals: |C + compliance/h^2 * lambda|,
 * in the kind's unit) is at or below EMBRA_SOLVE_RESIDUAL_TARGET_M, _RAD or _M3 by that unit (a
 * stretched inextensible chain, a pin off its target or a compliant constraint whose step has not
 * converged is out of tolerance, however still it stands); or until max_frames frames or
 * max_seconds of wall time. At rest but out of tolerance, it steps on while the worst of those
 * metrics (value over target) still falls by 1 % every hold_frames frames. Still moving at the end,
 * the motion is told apart as oscillating (back and forth with a period: the paper's "oscillates
 * between two saddle states", a pendulum) or drifting: three fixed random projections of the
 * movable particles' positions are recorded every frame, and over the last three quarters of the
 * frames the one that varies most, less its trend, must rise through zero at least three times at
 * intervals within 10 % of their mean, the period.
 * A loaded scene's actions (pins drawn in, colliders moved on a schedule) are part of the problem:
 * at rest before the frame of their last key does not count.
 * A step that fails ends the call with its status (the world as before that frame; the frames
 * before it stay stepped; *out_result says how many).
 * ------------------------------------------------------------------------------------------- */

enum {
  EMBRA_SOLVE_UNTIL_SETTLED = 0,  /* at rest */
  EMBRA_SOLVE_UNTIL_TOLERANCE = 1 /* at rest, every panel mesh within its tolerance targets and every
                                     kind's residual within its residual target */
};

/* The residual targets of "within tolerance", by the unit of a kind's residual (embra_residual_unit). */
#define EMBRA_SOLVE_RESIDUAL_TARGET_M 1e-4   /* m (lengths, pins, contacts): 0.1 mm */
#define EMBRA_SOLVE_RESIDUAL_TARGET_RAD 1e-3 /* rad (angles) */
#define EMBRA_SOLVE_RESIDUAL_TARGET_M3 1e-9  /* m^3 (volumes): a cube of 1 mm */
/* embra_solve_result.worst_metric for a kind's constraint residual above its target. */
#define EMBRA_SOLVE_WORST_RESIDUAL 16

#define EMBRA_SOLVE_DEF_VERSION 1
typedef struct embra_solve_def {
  int32_t version;     /* EMBRA_SOLVE_DEF_VERSION */
  int32_t until;       /* EMBRA_SOLVE_UNTIL_*; default EMBRA_SOLVE_UNTIL_TOLERANCE */
  int32_t max_frames;  /* frame budget, >= 1; default 1000 */
  int32_t hold_frames; /* frames in a row at rest that count as settled, >= 1; default 10 */
  double max_seconds;  /* wall-clock budget in s, >= 0 (0: none); default 0. With one, where the
                          stepping stops depends on the machine (each frame is the same bits) */
} embra_solve_def;

enum {
  EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE = 0, /* at rest, every panel mesh and residual within its targets */
  EMBRA_SOLVE_SETTLED_OUT_OF_TOLERANCE = 1, /* at rest, worst_* above its target: no solution nearby */
  EMBRA_SOLVE_OSCILLATING = 2,              /* still moving back and forth, with `period` */
  EMBRA_SOLVE_DRIFTING = 3                  /* still moving, no period */
};

typedef struct embra_solve_result {
  int32_t outcome;          /* EMBRA_SOLVE_SETTLED_WITHIN_TOLERANCE ... EMBRA_SOLVE_DRIFTING */
  int32_t frames;           /* frames stepped by the call */
  double period;            /* s, EMBRA_SOLVE_OSCILLATING: the motion's period; else 0 */
  int32_t worst_metric;     /* the metric furthest above its target at the end (value / target), as
                               EMBRA_PANEL_METRIC_PLANARITY, _CORNER_DISTANCE, _THICKNESS or _MITER,
                               or EMBRA_SOLVE_WORST_RESIDUAL (a kind's residual above its target:
                               worst_element is the kind, EMBRA_CONSTRAINT_* or EMBRA_RESIDUAL_PINS /
                               _CONTACTS; worst_body none); -1 when the world has no panel mesh and
                               every residual is within its target */
  int32_t worst_layer;      /* 0 top, 1 bottom (planarity, corner distance); -1 otherwise */
  embra_body_id worst_body; /* the panel mesh */
  int32_t worst_element;    /* panel (planarity, corner distance, thickness) or joint (miter: edge of
                               the top mesh, in order of first appearance around the panels) */
  int32_t reserved0;
  double worst_value;  /* in the metric's unit (1 - n1.n2, or m) */
  double worst_target; /* the world's tolerance target for it */
} embra_solve_result;

EMBRA_API embra_solve_def embra_default_solve_def(void);
/* def nullable (the defaults); *out_result (required) is written also when a step fails. */
EMBRA_API embra_status embra_world_solve(embra_world* world, const embra_solve_def* def,
                                         embra_solve_result* out_result);

typedef struct embra_warning {
  int64_t frame;    /* frame of the last numerical failure, -1 if none */
  int32_t particle; /* first particle non-finite or beyond EMBRA_MAX_ABS_VALUE, -1 if none */
  int32_t reserved0;
} embra_warning;

EMBRA_API embra_status embra_world_get_warning(const embra_world* world, embra_warning* out_warning);

/* Copies `count` particles' positions (m) starting at `first` into out_xyz (capacity in doubles,
 * at least 3 * count). */
EMBRA_API embra_status embra_world_get_positions(const embra_world* world, double* out_xyz, int64_t capacity,
                                                 int32_t first, int32_t count);
/* Same for velocities (m/s). */
EMBRA_API embra_status embra_world_get_velocities(const embra_world* world, double* out_xyz, int64_t capacity,
                                                  int32_t first, int32_t count);
/* Moves `count` particles starting at `first` to xyz (double[3 * count]); velocities are kept. */
EMBRA_API embra_status embra_world_set_positions(embra_world* world, const double* xyz, int32_t first, int32_t count);
/* Sets `count` particles' velocities (m/s). */
EMBRA_API embra_status embra_world_set_velocities(embra_world* world, const double* xyz, int32_t first, int32_t count);
/* Sets `count` particles' point loads (N, xyz per particle, double[3 * count], each coordinate finite
 * and within +-1e300) starting at `first`: forces applied every substep beside gravity, until set
 * again (0 by default; a hard-pinned particle's load goes to its pin's reaction). */
EMBRA_API embra_status embra_world_set_loads(embra_world* world, const double* xyz, int32_t first, int32_t count);
/* Copies `count` particles' point loads (N) starting at `first` into out_xyz (capacity in doubles). */
EMBRA_API embra_status embra_world_get_loads(const embra_world* world, double* out_xyz, int64_t capacity, int32_t first,
                                             int32_t count);

/* Area loads: a pressure (Pa) on the triangle of three distinct particles, its force
 * a third on each corner, applied every substep beside gravity from the positions at the substep's
 * start, and counted in the reactions (embra_world_get_reactions). With the vector area
 * a = (x1 - x0) x (x2 - x0) / 2 and u = direction / |direction|, the triangle's force is
 *   EMBRA_AREA_LOAD_NORMAL          pressure * a: along the normal, following the surface as it
 *                                   moves (wind pressure, inflation; negative: suction)
 *   EMBRA_AREA_LOAD_TRUE_AREA       pressure * |a| * u: a fixed direction per m^2 of the triangle
 *                                   (the self-weight of a cover)
 *   EMBRA_AREA_LOAD_PROJECTED_AREA  pressure * |a . u| * u: a fixed direction per m^2 of the
 *                                   triangle's projection on the plane normal to u (snow on the
 *                                   plan area, u vertical)
 * A triangle that comes to zero area feels no force. On a closed surface wound counter-clockwise
 * seen from outside, NORMAL with pressure p pushes each vertex by p times the gradient of the
 * enclosed volume. */
enum { EMBRA_AREA_LOAD_NORMAL = 0, EMBRA_AREA_LOAD_TRUE_AREA = 1, EMBRA_AREA_LOAD_PROJECTED_AREA = 2 };

typedef struct embra_area_load {
  int32_t particles[3]; /* world particle indices, distinct */
  int32_t mode;         /* EMBRA_AREA_LOAD_* */
  double pressure;      /* Pa (N/m^2), finite */
  double direction[3];  /* the fixed modes' direction: finite, of any nonzero length (kept as given,
                           used as a unit vector); read but not used by EMBRA_AREA_LOAD_NORMAL */
} embra_area_load;

/* Replaces the world's area loads with loads[0 .. count) (count 0: none; loads may then be NULL),
 * from the next step on: change them between steps by setting them again. Refused, changing
 * nothing: a particle out of range, a repeated corner (a degenerate triangle), an unknown mode, a
 * pressure or direction coordinate not finite within +-1e300, a fixed mode's zero direction (or one
 * too short to normalise), count < 0. Saved in a scene as "area_loads". */
EMBRA_API embra_status embra_world_set_area_loads(embra_world* world, const embra_area_load* loads, int32_t count);
/* The world's area loads as set. Two-call pattern: out NULL and capacity 0 only write *out_count;
 * a smaller capacity is EMBRA_ERROR_BUFFER_TOO_SMALL, nothing written. Capacity in loads. */
EMBRA_API embra_status embra_world_get_area_loads(const embra_world* world, embra_area_load* out, int32_t capacity,
                                                  int32_t* out_count);

/* Line loads: a force per metre (N/m) of the current length of the edge between two distinct
 * particles, along a fixed direction, half on each end; applied and counted as the area loads. */
typedef struct embra_line_load {
  int32_t particles[2]; /* world particle indices, distinct */
  double load[3];       /* N/m, finite */
} embra_line_load;

/* Replaces the world's line loads, as embra_world_set_area_loads (refused likewise: an edge
 * joining a particle to itself is degenerate). Saved in a scene as "line_loads". */
EMBRA_API embra_status embra_world_set_line_loads(embra_world* world, const embra_line_load* loads, int32_t count);
/* The world's line loads as set (two-call pattern, as embra_world_get_area_loads). */
EMBRA_API embra_status embra_world_get_line_loads(const embra_world* world, embra_line_load* out, int32_t capacity,
                                                  int32_t* out_count);

/* ---------------------------------------------------------------------------------------------
 * Geometry queries
 * ------------------------------------------------------------------------------------------- */

/* Copies a body's triangles as world particle indices (int32_t[3 * triangle count]) into out
 * (capacity in int32 values). *out_count (required) receives the number of int32 values the
 * triangles take; with out NULL and capacity 0 only the count is written (EMBRA_OK). */
EMBRA_API embra_status embra_body_get_triangles(const embra_world* world, embra_body_id body, int32_t* out,
                                                int64_t capacity, int64_t* out_count);

/* The world as Wavefront OBJ text (UTF-8, NUL-terminated): the line "# embra <version>", every
 * particle as a `v` line in world order (%.17g: each double exactly; OBJ vertex k + 1 is particle
 * k), then per body a group `g body_<index>` holding its triangles as `f` lines or, for a body
 * without triangles (a hanging net, a chain), its edges as `l` lines: the edges it was made of
 * (given, or its tetrahedra's) and every distance constraint added between two of its particles,
 * each pair once, lower particle first, in increasing order. A body with neither (loose particles)
 * has no group. Two-call pattern as embra_world_save_json: *out_length includes the terminating NUL. */
EMBRA_API embra_status embra_world_export_obj(const embra_world* world, char* out, int64_t capacity,
                                              int64_t* out_length);
/* The same OBJ text written to a file (replaced whole; no partial file on failure). */
EMBRA_API embra_status embra_world_write_obj(const embra_world* world, const char* path);

/* ---------------------------------------------------------------------------------------------
 * Panel meshes: Planar Offset Quads (the paper's section 4)
 *
 * A panel mesh is built from a quad mesh, the top layer, given as vertices and quads or as an
 * n x m grid of square panels. Each quad becomes a panel, welded (the default: 8 particles of its
 * own in the body; panel p: top corners first + 8p + 0..3, bottom corners first + 8p + 4..7, corner
 * k on quad vertex k) or sharing its corners (2 particles a mesh vertex v: top first + v, bottom
 * first + vertex_count + v; embra_panel_mesh_get_corner_particles gives either): the top quad
 * braced rigid (4 edges and 2 diagonals, hard) and held planar (EMBRA_CONSTRAINT_PLANARITY),
 * welded: the corners of adjacent panels on one mesh vertex welded top and bottom (panels pivot
 * about their borders), each bottom corner held `thickness` below the plane of its top corner's
 * triangle (EMBRA_CONSTRAINT_PLANE_OFFSET: it slides along it), every edge's joint (miter face:
 * the edge's two top and two bottom corners) held planar, and a soft distance from each bottom
 * corner to its top corner (slide_compliance) for where nothing else decides its place. The
 * initial bottom corner of a mesh vertex is where the offset planes of its faces meet (least
 * squares; exact for a conical mesh). The triangles of both layers (bottom ones facing down) take
 * face contacts against sphere colliders, so a rigid panel never passes into a sphere between its
 * corners; a contact pushes the panel as a slab (each corner of the touching face together with the
 * corner across the thickness from it, as one particle of their joint mass), so the push does not
 * fight the plane offsets; a corner whose partner is hard-pinned is not pushed.
 *
 * Metrics (section 4.1, computed from positions alone): planarity 1 - n1.n2 of the unit normals of
 * a quad's two triangles (the larger over both diagonals; dimensionless, quadratic in the fold),
 * the largest distance of a quad's corner from the plane of the other three (model units), the
 * distance between its diagonals over its mean edge length, thickness error (the largest
 * |distance - thickness| of a corner of one layer from the plane of the corresponding corner
 * triangle of the other), miter twist (distance of a joint's fourth point, bottom corner j, from the
 * plane through top i, top j and bottom i), and the conical defect |(a1 + a3) - (a2 + a4)| of the
 * face angles at interior vertices of valence 4 (radians; 0 for a conical mesh, whose face offset
 * exists, so it explains miter error).
 * ------------------------------------------------------------------------------------------- */

enum {
  EMBRA_PANEL_PINS_NONE = 0,
  EMBRA_PANEL_PINS_TOP_CORNERS = 1,           /* hard pins at the top corners of the mesh's corners */
  EMBRA_PANEL_PINS_TOP_AND_BOTTOM_CORNERS = 2 /* and at their bottom corners */
};

/* How the panels on one mesh vertex hold together (embra_panel_mesh_def.corners). */
enum {
  EMBRA_PANEL_CORNERS_WELDED = 0, /* 8 particles a panel (its top corners 0-3, then its bottom corners
                                     0-3, panel after panel); the corners on one vertex welded (hard) */
  EMBRA_PANEL_CORNERS_SHARED = 1  /* 2 particles a vertex (the top layer's vertices in order, then the
                                     bottom layer's) that its panels share: no welds, the offset quads
                                     round a vertex meet in one point exactly (the paper's POQ
                                     condition), so the top mesh is held conical; about 4 times fewer
                                     particles, and the load reaches the pins in fewer iterations */
};

/* The arithmetic of a panel mesh's own rows, its panels' edges, diagonals, planarity and plane offsets
 * (embra_panel_mesh_def.precision). Positions, contacts, welds and every other constraint stay in
 * double precision. */
enum {
  EMBRA_PANEL_PRECISION_FULL = 0,  /* double precision, as every other constraint */
  EMBRA_PANEL_PRECISION_SINGLE = 1 /* single precision, each panel relative to its first corner and its
                                      corners' moves summed from zero within a projection, then added to
                                      the double positions; twice the lanes a vector instruction holds.
                                      The 32 x 32 drape (examples/large/poq_drape_32.json) takes 40 %
                                      less time a frame (27.6 ms against 44.5, embra run), and meets every target of its
                                      tolerance document from frame 183 (178 in full precision). A corner resolves to
                                      about 6e-8 of its panel's size (the float's rounding), so a mesh at rest is still
                                      only to about that over a substep: at frame 300 the 32 x 32 drape
                                      (0.1 m panels, 50 substeps a frame) moves at 8.1e-5 m/s and the
                                      4 x 4 paper drape (0.8 m, 60) at 5.0e-4, against 2.1e-5 and 5.5e-6
                                      in full precision, the same relative to the panels' size from 0.7 mm
                                      to 700 m panels. For large meshes of small panels, where
                                      the rows are most of a frame and settle_speed is well above that */
};

#define EMBRA_PANEL_MESH_DEF_VERSION 2
typedef struct embra_panel_mesh_def {
  int32_t version;         /* EMBRA_PANEL_MESH_DEF_VERSION */
  int32_t vertex_count;    /* top mesh vertices; 0: build the grid below instead */
  const double* positions; /* double[3 * vertex_count], model units (m) */
  const int32_t* quads;    /* int32_t[4 * quad_count], counter-clockwise seen from the top's normal
                              side (the bottom layer is offset to the other side); consistently
                              oriented, every edge on at most two quads, each quad planar within
                              the world's tolerances (embra_world_set_tolerances; the defaults
                              when none were set): planarity (1 - n1.n2) at most
                              planarity.target (the corner distance is reported in the metrics,
                              not checked here) */
  int32_t quad_count;
  int32_t grid_columns;    /* grid (vertex_count 0): panels along +x (>= 1); default 4 */
  int32_t grid_rows;       /* panels along +y (>= 1); default 4 */
  int32_t pins;            /* EMBRA_PANEL_PINS_*; default EMBRA_PANEL_PINS_NONE */
  double panel_size;       /* grid: side of a square panel (m, > 0); default 0.8 */
  double origin[3];        /* grid: corner of panel 0 (m); the grid lies in z = origin[2]; default 0 */
  double thickness;        /* panel thickness (m, > 0); default 0.01 */
  double mass;             /* kg for the whole mesh when > 0; default 0 (use density) */
  double density;          /* kg per m^2 of top area when mass is 0; default 1 */
  double damping;          /* 1/s per particle; default 0 */
  double friction_static;  /* against colliders; default 0.5 */
  double friction_dynamic; /* default 0.3 */
  double slide_compliance; /* m/N of the bottom-to-top soft distance (>= 0; 0 = none); default 1e-3 */
  embra_group_id group;    /* group of every constraint; {0,0} = default group */
  int32_t corners;         /* EMBRA_PANEL_CORNERS_*; default EMBRA_PANEL_CORNERS_WELDED. Shared: every
                              vertex must be on a quad */
  int32_t precision;       /* EMBRA_PANEL_PRECISION_*; default EMBRA_PANEL_PRECISION_FULL. This field
                              was reserved0 (always 0) before: hosts that zero it keep full precision */
} embra_panel_mesh_def;

EMBRA_API embra_panel_mesh_def embra_default_panel_mesh_def(void);
/* Builds a panel mesh: a body, its constraints, its pins. *out_body (required) receives the body;
 * *out_first_particle (nullable) its first particle. Everything is checked first; a refused call
 * creates nothing. */
EMBRA_API embra_status embra_panel_mesh_create(embra_world* world, const embra_panel_mesh_def* def,
                                               embra_body_id* out_body, int32_t* out_first_particle);
/* Number of panels of a panel-mesh body (EMBRA_ERROR_INVALID_ARGUMENT if the body is not one). */
EMBRA_API embra_status embra_panel_mesh_get_panel_count(const embra_world* world, embra_body_id body,
                                                        int32_t* out_count);
/* The world particle of each panel corner: 8 a panel, its top corners 0-3 then its bottom corners
 * 0-3 (corner k on the panel's quad vertex k), panel after panel; *out_count = 8 * panels. Corners
 * of panels on one vertex are distinct particles when welded, one particle when shared. */
EMBRA_API embra_status embra_panel_mesh_get_corner_particles(const embra_world* world, embra_body_id body, int32_t* out,
                                                             int64_t capacity, int64_t* out_count);

typedef struct embra_tolerance {
  double target; /* at or below: within tolerance (drawn grey) */
  double max;    /* the colour scale's end; above: out of tolerance */
} embra_tolerance;

#define EMBRA_TOLERANCES_VERSION 1
/* schemas/tolerances.schema.json as a struct. */
typedef struct embra_tolerances {
  int32_t version; /* EMBRA_TOLERANCES_VERSION */
  int32_t reserved0;
  double unit_scale;                  /* mm per metre of panel per model unit; default 1000 */
  embra_tolerance planarity;          /* 1 - n1.n2; default {1e-6, 1e-4} */
  embra_tolerance planarity_distance; /* corner off the plane of the other three (m); {5e-5, 1e-3} */
  embra_tolerance thickness;          /* m; default {5e-5, 1e-3} (the paper's) */
  embra_tolerance miter;              /* m; default {1e-3, 1e-2} (the paper's target) */
} embra_tolerances;

EMBRA_API embra_tolerances embra_default_tolerances(void);
/* The world's tolerances: the scene's tolerance document where it has one, else the defaults. */
EMBRA_API embra_status embra_world_get_tolerances(const embra_world* world, embra_tolerances* out_tolerances);
/* Sets the world's tolerances (saved with the scene). Every value finite, >= 0, target <= max,
 * unit_scale > 0. */
EMBRA_API embra_status embra_world_set_tolerances(embra_world* world, const embra_tolerances* tolerances);

typedef struct embra_metric_summary {
  double max;
  double rms;
  int64_t count;         /* elements measured (panels, joints or vertices) */
  int64_t within_target; /* <= target */
  int64_t within_max;    /* > target and <= max */
  int64_t above_max;     /* > max */
} embra_metric_summary;

#define EMBRA_PANEL_METRICS_VERSION 1
typedef struct embra_panel_metrics {
  int32_t version;          /* set by the library: EMBRA_PANEL_METRICS_VERSION */
  int32_t within_tolerance; /* 1: planarity (both layers), corner distance, thickness and miter
                               all at or below their targets */
  embra_metric_summary planarity_top, planarity_bottom;             /* per panel, 1 - n1.n2 */
  embra_metric_summary corner_distance_top, corner_distance_bottom; /* per panel, m */
  embra_metric_summary diagonal_top, diagonal_bottom;               /* per panel, diagonals' distance / mean edge */
  embra_metric_summary thickness;                                   /* per panel, m */
  embra_metric_summary miter;                                       /* per joint (edge of the top mesh), m */
  embra_metric_summary conical;                                     /* per interior valence-4 vertex, rad */
} embra_panel_metrics;

/* Measures a panel-mesh body at the current positions against `tolerances` (nullable: the world's).
 * Counts for diagonal and conical are against a target of 0. This call, _get_corner_gap and
 * _get_vertex_errors share one measurement while the body's particles keep their positions bit for
 * bit: a frame's metrics and every error field cost one (0.32-0.33 ms on the 2,178 particles of
 * examples/large/poq_drape_32.json; each further read 0.01-0.03 ms). */
EMBRA_API embra_status embra_panel_mesh_get_metrics(const embra_world* world, embra_body_id body,
                                                    const embra_tolerances* tolerances,
                                                    embra_panel_metrics* out_metrics);

/* The welds' error, which the paper's metrics do not see: for every mesh vertex shared by two or
 * more panels, the largest distance between two of its corner copies in one layer (top or bottom),
 * in model units; 0 when the panels meet exactly. Counts are against a target of 0. Gauss-Seidel
 * leaves it largest on big meshes under load (bench/README.md, POQ drape). */
EMBRA_API embra_status embra_panel_mesh_get_corner_gap(const embra_world* world, embra_body_id body,
                                                       embra_metric_summary* out_summary);

enum {
  EMBRA_PANEL_METRIC_PLANARITY = 0,       /* 1 - n1.n2 of the particle's layer of its panel */
  EMBRA_PANEL_METRIC_THICKNESS = 1,       /* m, its panel's thickness error */
  EMBRA_PANEL_METRIC_MITER = 2,           /* m, the largest twist of the joints it is a corner of */
  EMBRA_PANEL_METRIC_CORNER_DISTANCE = 3, /* m, its layer's corner distance */
  EMBRA_PANEL_METRIC_CONICAL = 4          /* rad, the conical defect at its mesh vertex (0 elsewhere) */
};
/* Per-vertex error field for colour maps (figures 12 and 13: grey at or below the target, shaded
 * up to the max): one double per particle of the body (in body order) into out
 * (capacity in doubles). *out_count (required) receives the count; out NULL and capacity 0 only
 * ask for it. */
EMBRA_API embra_status embra_panel_mesh_get_vertex_errors(const embra_world* world, embra_body_id body, int32_t metric,
                                                          double* out, int64_t capacity, int64_t* out_count);

enum { EMBRA_CUTS_JSON = 0, EMBRA_CUTS_CSV = 1 };
/* The cut list at the current positions: per panel its top and bottom outlines in the panel's own
 * plane coordinates (origin top corner 0, x along its first edge, y in the top plane, z along the
 * top normal), its thickness, the bottom plane's z, and the miter angle of each edge k (corner k to
 * k + 1) in degrees (0 = square cut, positive = the bottom reaches outward), as JSON
 * ({"format": "embra-panel-cuts", ...}) or CSV (one row per panel, header first). Two-call
 * pattern as embra_world_save_json: *out_length includes the terminating NUL. */
EMBRA_API embra_status embra_panel_mesh_export_cuts(const embra_world* world, embra_body_id body, int32_t format,
                                                    char* out, int64_t capacity, int64_t* out_length);

/* ---------------------------------------------------------------------------------------------
 * JSON scenes (schemas/scene.schema.json): the same world through a second door
 *
 * A scene is validated against the schema before anything is built; an invalid scene returns
 * EMBRA_ERROR_SCHEMA with a message starting with the JSON pointer of the offending value, and
 * creates nothing. A saved scene holds the complete world and its state: loading it gives a world
 * that steps bit-identically to the one saved. Scene actions (rest-scale ramps, pin paths,
 * collider paths, gravity changes) are applied by embra_world_step before each frame, until the
 * host sets the same thing itself (embra_pin_set_target, embra_collider_set_transform,
 * embra_world_set_gravity, embra_body_set_rest_scale): then the host's value holds.
 * ------------------------------------------------------------------------------------------- */

/* Builds a world from scene JSON text of `length` bytes. `base_dir` (nullable: ".") resolves
 * relative OBJ paths; an OBJ path must be relative and stay inside base_dir (no absolute path,
 * no ".." or symbolic link leading out), name a regular file (no device, pipe or folder) and be
 * at most EMBRA_MAX_OBJ_BYTES. On failure *out_world is NULL. */
EMBRA_API embra_status embra_world_load_json(embra_world** out_world, const char* json, int64_t length,
                                             const char* base_dir);
/* Same, from a file (relative paths resolve against the file's folder, and stay inside it). The
 * file must be a regular file of at most 2 GiB (a folder, device or pipe is refused without being
 * read or waited on): otherwise EMBRA_ERROR_INVALID_ARGUMENT. */
EMBRA_API embra_status embra_world_load_file(embra_world** out_world, const char* path);

#define EMBRA_LOAD_OPTIONS_VERSION 1
typedef struct embra_load_options {
  int32_t version;                  /* EMBRA_LOAD_OPTIONS_VERSION */
  int32_t allow_paths_outside_base; /* 1: OBJ paths may be absolute or lead out of base_dir; 0 */
  const char* base_dir;             /* relative OBJ paths resolve here; NULL: "." */
} embra_load_options;
EMBRA_API embra_load_options embra_default_load_options(void);
/* embra_world_load_json with options: for a host that lets a scene read OBJ files anywhere
 * (scenes it trusts), or names the folder. */
EMBRA_API embra_status embra_world_load_json_with_options(embra_world** out_world, const char* json, int64_t length,
                                                          const embra_load_options* options);
/* Writes the world as scene JSON (UTF-8, NUL-terminated) into out. *out_length (required)
 * receives the size in bytes including the terminating NUL; call with out NULL and capacity 0 to
 * learn it. Too small a buffer: EMBRA_ERROR_BUFFER_TOO_SMALL, nothing written. */
EMBRA_API embra_status embra_world_save_json(const embra_world* world, char* out, int64_t capacity,
                                             int64_t* out_length);
/* Writes the world as scene JSON to a file (replaced whole; no partial file on failure). */
EMBRA_API embra_status embra_world_save_file(const embra_world* world, const char* path);
/* The scene's own frame count ("frames"; 600 for a world not loaded from a scene). */
EMBRA_API embra_status embra_world_get_scene_frames(const embra_world* world, int64_t* out_frames);

/* ---------------------------------------------------------------------------------------------
 * Fields: forces and whole-body constraints beside gravity (the paper's section 3)
 *
 * A field acts in every substep of every step until destroyed. Forces are evaluated at the start of
 * each substep from the positions and velocities there and change the velocities of movable
 * particles (as gravity does; hard-pinned and immovable particles are not moved by them). A
 * pressure field's volume constraint is projected with XPBD before the groups in every pass.
 * A field's parameters change between steps with embra_*_set (its kind and body stay those it was
 * created with) and read back with embra_*_get.
 * ------------------------------------------------------------------------------------------- */

typedef struct embra_field_id {
  uint32_t index;
  uint32_t generation;
} embra_field_id;

/* Wind: each triangle of the body (or of every body) feels the air flowing at
 * `speed` * `direction` relative to the triangle's own velocity u (the mean of its corners'), with
 * q = 0.5 * air_density * |u|^2 * area and c = cos(angle between u and the triangle's normal n):
 *   drag = q * drag * |c| * u/|u|              (along the flow, in proportion to the area facing it)
 *   lift = q * lift * c * (n - c * u/|u|)      (across the flow: a flat plate's normal force, the
 *                                               part perpendicular to the flow)
 * a third of each on each corner. Drag and lift against stretch make a flag flap. */
#define EMBRA_WIND_DEF_VERSION 1
typedef struct embra_wind_def {
  int32_t version;     /* EMBRA_WIND_DEF_VERSION */
  int32_t reserved0;   /* 0 */
  embra_body_id body;  /* the body whose triangles feel the wind; {0,0} (default) = every body */
  double direction[3]; /* where the air goes, any length but not zero; default {1, 0, 0} */
  double speed;        /* m/s, >= 0; default 0 */
  double air_density;  /* kg/m^3, >= 0; default 1.2 (air at sea level) */
  double drag;         /* drag coefficient, >= 0; default 1 */
  double lift;         /* lift coefficient, >= 0; default 1 */
} embra_wind_def;

EMBRA_API embra_wind_def embra_default_wind_def(void);
/* Refused for a stale body id, a body without triangles, a zero or non-finite direction, or a
 * negative or non-finite number. */
EMBRA_API embra_status embra_wind_create(embra_world* world, const embra_wind_def* def, embra_field_id* out_field);
/* Checked as embra_wind_create checks it; refused for a field of another kind or def.body other
 * than the field's. */
EMBRA_API embra_status embra_wind_set(embra_world* world, embra_field_id field, const embra_wind_def* def);
EMBRA_API embra_status embra_wind_get(const embra_world* world, embra_field_id field, embra_wind_def* out_def);

/* Air pressure on a closed body (every edge shared by two triangles, wound counter-clockwise seen
 * from outside): each triangle is pushed along its outward normal by
 * (inside_pressure - outside_pressure) * area, a third on each corner. Inside 0 and a normal
 * pressure outside sucks a shrink-wrap surface into the concavities of what it wraps. With
 * keep_volume 1 the enclosed volume V is also held at rest_volume by an XPBD constraint
 * V - rest_volume + volume_compliance * p = 0 (p the constraint's pressure, Pa). */
#define EMBRA_PRESSURE_DEF_VERSION 1
typedef struct embra_pressure_def {
  int32_t version;          /* EMBRA_PRESSURE_DEF_VERSION */
  int32_t keep_volume;      /* 0 (default) or 1: hold the enclosed volume at rest_volume */
  embra_body_id body;       /* required: a closed body */
  double inside_pressure;   /* Pa (N/m^2), finite; default 0 */
  double outside_pressure;  /* Pa, finite; default 0 */
  double volume_compliance; /* m^3/Pa, >= 0; 0 (default) = incompressible */
  double rest_volume;       /* m^3, >= 0; 0 (default) = the volume the body encloses at creation */
} embra_pressure_def;

EMBRA_API embra_pressure_def embra_default_pressure_def(void);
/* Refused for a missing or stale body, a body that is not closed and consistently wound, one that
 * encloses no positive volume (wound inwards), keep_volume other than 0 or 1, or a negative or
 * non-finite number. */
EMBRA_API embra_status embra_pressure_create(embra_world* world, const embra_pressure_def* def,
                                             embra_field_id* out_field);
/* As embra_wind_set; rest_volume 0 is the volume enclosed now. embra_pressure_get gives the rest
 * volume in use (measured at creation when it was 0). */
EMBRA_API embra_status embra_pressure_set(embra_world* world, embra_field_id field, const embra_pressure_def* def);
EMBRA_API embra_status embra_pressure_get(const embra_world* world, embra_field_id field, embra_pressure_def* out_def);

/* Surface tension: a soap-film material on a body's triangles. The force on each vertex is
 * -tension * d(area)/dx, so a settled film between fixed boundaries is a minimal surface whatever
 * the mesh (edge springs shrunk towards zero minimise the sum of squared edge lengths instead, which
 * is a minimal surface only on a conformal mesh). Area alone does not care where the vertices sit
 * on the surface, so a tangential regularisation spaces them: regularisation * tension * (mean of
 * the neighbours - x), with its component along the vertex normal removed, so it never changes the
 * shape. Use it without stretch constraints (generate only what else you need) and with damping. */
#define EMBRA_SURFACE_TENSION_DEF_VERSION 1
typedef struct embra_surface_tension_def {
  int32_t version;       /* EMBRA_SURFACE_TENSION_DEF_VERSION */
  int32_t reserved0;     /* 0 */
  embra_body_id body;    /* required: a body with triangles */
  double tension;        /* N/m, >= 0; default 0 */
  double regularisation; /* dimensionless, >= 0; default 1 */
} embra_surface_tension_def;

EMBRA_API embra_surface_tension_def embra_default_surface_tension_def(void);
/* Refused for a missing or stale body, a body without triangles, or a negative or non-finite
 * number. */
EMBRA_API embra_status embra_surface_tension_create(embra_world* world, const embra_surface_tension_def* def,
                                                    embra_field_id* out_field);
EMBRA_API embra_status embra_surface_tension_set(embra_world* world, embra_field_id field,
                                                 const embra_surface_tension_def* def);
EMBRA_API embra_status embra_surface_tension_get(const embra_world* world, embra_field_id field,
                                                 embra_surface_tension_def* out_def);

/* Vortex: a volumetric torsion field about an axis through `center`. A particle at offset d from
 * the axis (r = |d|) and height s along it is accelerated (whatever its mass) by
 *   a = strength * exp(-decay * (t - start_time)) * (1 + twist * s) * exp(-r^2 / radius^2)
 *       * (axis x d) / radius                      for world time t >= start_time (0 before),
 * a swirl that fades with distance from the axis, varies along it (twist: torsion) and dies out
 * over time so the form can settle. */
#define EMBRA_VORTEX_DEF_VERSION 1
typedef struct embra_vortex_def {
  int32_t version;    /* EMBRA_VORTEX_DEF_VERSION */
  int32_t reserved0;  /* 0 */
  embra_body_id body; /* the body it acts on; {0,0} (default) = every particle */
  double center[3];   /* m; default {0, 0, 0} */
  double axis[3];     /* any length but not zero; right-handed turn; default {0, 0, 1} */
  double strength;    /* m/s^2, finite (negative turns the other way); default 0 */
  double radius;      /* m, > 0: radial falloff; default 1 */
  double twist;       /* 1/m, finite: strength change along the axis; default 0 */
  double decay;       /* 1/s, >= 0; default 0 (no decay) */
  double start_time;  /* s of world time, finite; default 0 */
} embra_vortex_def;

EMBRA_API embra_vortex_def embra_default_vortex_def(void);
/* Refused for a stale body id, a zero or non-finite axis, radius <= 0, a negative decay or a
 * non-finite number. */
EMBRA_API embra_status embra_vortex_create(embra_world* world, const embra_vortex_def* def, embra_field_id* out_field);
EMBRA_API embra_status embra_vortex_set(embra_world* world, embra_field_id field, const embra_vortex_def* def);
EMBRA_API embra_status embra_vortex_get(const embra_world* world, embra_field_id field, embra_vortex_def* out_def);

/* Destroys a field; its id becomes stale. */
EMBRA_API embra_status embra_field_destroy(embra_world* world, embra_field_id field);
/* Number of live fields. */
EMBRA_API embra_status embra_world_get_field_count(const embra_world* world, int32_t* out_count);

#ifdef __cplusplus
}
#endif

#endif /* EMBRA_EMBRA_H */
