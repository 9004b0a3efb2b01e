// The C ABI of libembra as P/Invoke sees it: structs mirrored field for field from
// capi/include/embra/embra.h, and one table of prototypes. To bind a function added to the header,
// add its line to Native (and a struct here for a new type); the test EveryHeaderFunctionIsBound
// fails until every EMBRA_API function has its extern.
using System;
using System.Runtime.InteropServices;

namespace Embra
{
    /// <summary>embra_status values.</summary>
    public static class Status
    {
        public const int Ok = 0;
        public const int InvalidArgument = -1;
        public const int StaleId = -2;
        public const int BufferTooSmall = -3;
        public const int Schema = -4;
        public const int Version = -5;
        public const int Locked = -6;
        public const int Numerical = -7;
        public const int Internal = -8;
        public const int Cancelled = -9;
    }

    /// <summary>EMBRA_MAX_* and EMBRA_MIN_POSITIVE: the ranges and limits of what a world accepts
    /// (beyond them: EMBRA_ERROR_INVALID_ARGUMENT). Meanings: embra.h, RANGES AND LIMITS.</summary>
    public static class Limits
    {
        public const double MaxAbsValue = 1e300;
        public const double MinPositive = 1e-300;
        public const double MaxDt = 1e6;
        public const double MaxUnitScale = 1e12;
        public const int MaxParticles = 2097152;
        public const int MaxConstraints = 16777216;
        public const int MaxPassesPerStep = 100000;
        public const long MaxObjBytes = 268435456;
    }

    public enum ConstraintKind { Distance = 0, EdgeAngle = 1, Dihedral = 2, TetVolume = 3, Weld = 4, Tether = 5, Planarity = 6, PlaneOffset = 7 }

    public enum ColliderShape { Plane = 0, Sphere = 1, Box = 2, Capsule = 3, Convex = 4, Mesh = 5 }

    [Flags]
    public enum Generate { None = 0, Stretch = 1, Shear = 2, Bend = 4, Volume = 8 }

    /// <summary>EMBRA_PANEL_PINS_*: which corners of a panel mesh embra_panel_mesh_create pins.</summary>
    public enum PanelPins { None = 0, TopCorners = 1, TopAndBottomCorners = 2 }

    /// <summary>EMBRA_PANEL_METRIC_*: the per-vertex error fields of embra_panel_mesh_get_vertex_errors.</summary>
    public enum PanelMetric { Planarity = 0, Thickness = 1, Miter = 2, CornerDistance = 3, Conical = 4 }

    /// <summary>EMBRA_CUTS_*: the formats of embra_panel_mesh_export_cuts.</summary>
    public enum CutsFormat { Json = 0, Csv = 1 }

    [StructLayout(LayoutKind.Sequential)]
    public struct GroupId { public uint Index, Generation; }
    [StructLayout(LayoutKind.Sequential)]
    public struct BodyId { public uint Index, Generation; }
    [StructLayout(LayoutKind.Sequential)]
    public struct PinId { public uint Index, Generation; }
    [StructLayout(LayoutKind.Sequential)]
    public struct ColliderId { public uint Index, Generation; }
    [StructLayout(LayoutKind.Sequential)]
    public struct FieldId { public uint Index, Generation; }

    /// <summary>embra_solver_def (EMBRA_SOLVER_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct SolverDef
    {
        public const int CurrentVersion = 1;
        public int Version, Substeps;
        public double Dt;
        public int Iterations, ChebyshevRhoMilli;
        public fixed double Gravity[3];
        public double Damping, SettleSpeed;
        public int Tethers, RealignPasses, SelfCollision, ChainSolve;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct WorldCounts
    {
        public int Particles, Bodies, Groups, Pins, Colliders, Reserved0;
        public long Constraints;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct GroupDef
    {
        public const int CurrentVersion = 1;
        public int Version, Order, Weight;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Material
    {
        public double Mass, Density, StretchCompliance, ShearCompliance, BendCompliance, VolumeCompliance, Damping,
            Thickness, FrictionStatic, FrictionDynamic;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct BodyDef
    {
        public const int CurrentVersion = 1;
        public int Version, VertexCount;
        public IntPtr Positions, Masses, Uvs;
        public int EdgeCount, TriangleCount;
        public IntPtr Edges, Triangles, Tets;
        public int TetCount, Generate;
        public Material Material;
        public GroupId StretchGroup, ShearGroup, BendGroup, VolumeGroup;
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ConstraintDef
    {
        public const int CurrentVersion = 1;
        public int Version, Kind;
        public GroupId Group;
        public fixed int Particles[4];
        public int RestFromCurrent, Reserved0;
        public double Rest, Compliance;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct ConstraintBatchDef
    {
        public const int CurrentVersion = 1;
        public int Version, Kind;
        public GroupId Group;
        public int Count, Reserved0;
        public IntPtr Particles, Rest, Compliances;
        public double Compliance;
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct PinDef
    {
        public const int CurrentVersion = 1;
        public int Version, Particle;
        public fixed double Target[3];
        public double Compliance;
        public GroupId Group;
    }

    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct ColliderDef
    {
        public const int CurrentVersion = 2;
        public int Version, Shape;
        public fixed double Position[3];
        public fixed double Rotation[4];
        public double Radius, Thickness, FrictionStatic, FrictionDynamic;
        public fixed double HalfExtents[3];
        public double HalfLength;
        public int VertexCount, TriangleCount;
        public IntPtr Vertices, Triangles;
    }

    /// <summary>embra_panel_mesh_def (EMBRA_PANEL_MESH_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct PanelMeshDef
    {
        public const int CurrentVersion = 1;
        public int Version, VertexCount;
        public IntPtr Positions, Quads;
        public int QuadCount, GridColumns, GridRows, Pins;
        public double PanelSize;
        public fixed double Origin[3];
        public double Thickness, Mass, Density, Damping, FrictionStatic, FrictionDynamic, SlideCompliance;
        public GroupId Group;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Tolerance
    {
        public double Target, Max;
    }

    /// <summary>embra_tolerances (EMBRA_TOLERANCES_VERSION 1): schemas/tolerances.schema.json as a struct.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct Tolerances
    {
        public const int CurrentVersion = 1;
        public int Version, Reserved0;
        public double UnitScale;
        public Tolerance Planarity, PlanarityDistance, Thickness, Miter;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct MetricSummary
    {
        public double Max, Rms;
        public long Count, WithinTarget, WithinMax, AboveMax;
    }

    /// <summary>embra_panel_metrics (EMBRA_PANEL_METRICS_VERSION 1).</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct PanelMetrics
    {
        public const int CurrentVersion = 1;
        public int Version, WithinTolerance;
        public MetricSummary PlanarityTop, PlanarityBottom, CornerDistanceTop, CornerDistanceBottom, DiagonalTop,
            DiagonalBottom, Thickness, Miter, Conical;
    }

    /// <summary>embra_wind_def (EMBRA_WIND_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct WindDef
    {
        public const int CurrentVersion = 1;
        public int Version, Reserved0;
        public BodyId Body;
        public fixed double Direction[3];
        public double Speed, AirDensity, Drag, Lift;
    }

    /// <summary>embra_pressure_def (EMBRA_PRESSURE_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct PressureDef
    {
        public const int CurrentVersion = 1;
        public int Version, KeepVolume;
        public BodyId Body;
        public double InsidePressure, OutsidePressure, VolumeCompliance, RestVolume;
    }

    /// <summary>embra_surface_tension_def (EMBRA_SURFACE_TENSION_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct SurfaceTensionDef
    {
        public const int CurrentVersion = 1;
        public int Version, Reserved0;
        public BodyId Body;
        public double Tension, Regularisation;
    }

    /// <summary>embra_vortex_def (EMBRA_VORTEX_DEF_VERSION 1). Units and defaults: embra.h.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public unsafe struct VortexDef
    {
        public const int CurrentVersion = 1;
        public int Version, Reserved0;
        public BodyId Body;
        public fixed double Center[3];
        public fixed double Axis[3];
        public double Strength, Radius, Twist, Decay, StartTime;
    }

    /// <summary>embra_load_options (EMBRA_LOAD_OPTIONS_VERSION 1): where a scene's OBJ paths resolve
    /// (BaseDir, a NUL-terminated UTF-8 string or IntPtr.Zero for ".") and whether they may leave it.</summary>
    [StructLayout(LayoutKind.Sequential)]
    public struct LoadOptions
    {
        public const int CurrentVersion = 1;
        public int Version, AllowPathsOutsideBase;
        public IntPtr BaseDir;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct StepReport
    {
        public long Frame;
        public double Time, KineticEnergy, MaxSpeed, ResidualMax, ResidualRms;
        public long ConstraintCount, ContactCount;
        public int Settled, Reserved0;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct GroupReport
    {
        public long Count;
        public double ResidualMax, ResidualRms;
    }

    [StructLayout(LayoutKind.Sequential)]
    public struct Warning
    {
        public long Frame;
        public int Particle, Reserved0;
    }

    /// <summary>The prototypes, one per exported function of embra.h. The world is passed as a raw
    /// pointer: <see cref="World"/> holds it in a SafeHandle and keeps it alive across each call.</summary>
    public static class Native
    {
        public const string Library = "embra";  // libembra.so: the assembly's folder, LD_LIBRARY_PATH, the system
        public const int AbiVersion = 0;        // the EMBRA_ABI_VERSION these bindings were written against
        const CallingConvention C = CallingConvention.Cdecl;

        // errors and versions
        [DllImport(Library, CallingConvention = C)] public static extern IntPtr embra_last_error_message();
        [DllImport(Library, CallingConvention = C)] public static extern IntPtr embra_status_name(int status);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_version();
        [DllImport(Library, CallingConvention = C)] public static extern IntPtr embra_version_string();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_abi_version();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_check_abi(int headerAbiVersion);
        // world and solver settings
        [DllImport(Library, CallingConvention = C)] public static extern SolverDef embra_default_solver_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_create(out IntPtr world, ref SolverDef def);
        [DllImport(Library, CallingConvention = C)] public static extern void embra_world_destroy(IntPtr world);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_solver(IntPtr world, out SolverDef def);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_set_solver(IntPtr world, ref SolverDef def);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_set_gravity(IntPtr world, double[] gravity);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_counts(IntPtr world, out WorldCounts counts);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_bodies(IntPtr world, [Out] BodyId[] ids, int capacity, out int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_groups(IntPtr world, [Out] GroupId[] ids, int capacity, out int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_pins(IntPtr world, [Out] PinId[] ids, int capacity, out int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_colliders(IntPtr world, [Out] ColliderId[] ids, int capacity, out int count);
        // groups
        [DllImport(Library, CallingConvention = C)] public static extern GroupDef embra_default_group_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_group_create(IntPtr world, ref GroupDef def, out GroupId group);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_group_destroy(IntPtr world, GroupId group);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_group_set_order(IntPtr world, GroupId group, int order);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_group_set_weight(IntPtr world, GroupId group, int weight);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_default_group(IntPtr world, out GroupId group);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_contact_group(IntPtr world, out GroupId group);
        // bodies
        [DllImport(Library, CallingConvention = C)] public static extern Material embra_default_material();
        [DllImport(Library, CallingConvention = C)] public static extern BodyDef embra_default_body_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_body_create(IntPtr world, ref BodyDef def, out BodyId body, out int firstParticle);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_body_get_particles(IntPtr world, BodyId body, out int first, out int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_body_set_rest_scale(IntPtr world, BodyId body, double scale, double scaleU, double scaleV);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_body_get_triangles(IntPtr world, BodyId body, [Out] int[] triangles, long capacity, out long count);
        // panel meshes (tolerances: one, or null for the world's)
        [DllImport(Library, CallingConvention = C)] public static extern PanelMeshDef embra_default_panel_mesh_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_create(IntPtr world, ref PanelMeshDef def, out BodyId body, out int firstParticle);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_get_panel_count(IntPtr world, BodyId body, out int count);
        [DllImport(Library, CallingConvention = C)] public static extern Tolerances embra_default_tolerances();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_tolerances(IntPtr world, out Tolerances tolerances);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_set_tolerances(IntPtr world, ref Tolerances tolerances);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_get_metrics(IntPtr world, BodyId body, [In] Tolerances[] tolerances, out PanelMetrics metrics);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_get_corner_gap(IntPtr world, BodyId body, out MetricSummary summary);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_get_vertex_errors(IntPtr world, BodyId body, int metric, [Out] double[] errors, long capacity, out long count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_panel_mesh_export_cuts(IntPtr world, BodyId body, int format, [Out] byte[] text, long capacity, out long length);
        // constraints
        [DllImport(Library, CallingConvention = C)] public static extern int embra_constraint_arity(int kind);
        [DllImport(Library, CallingConvention = C)] public static extern ConstraintDef embra_default_constraint_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_constraint_add(IntPtr world, ref ConstraintDef def);
        [DllImport(Library, CallingConvention = C)] public static extern ConstraintBatchDef embra_default_constraint_batch_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_constraints_add(IntPtr world, ref ConstraintBatchDef def);
        // pins
        [DllImport(Library, CallingConvention = C)] public static extern PinDef embra_default_pin_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pin_create(IntPtr world, ref PinDef def, out PinId pin);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pin_destroy(IntPtr world, PinId pin);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pin_set_target(IntPtr world, PinId pin, double[] target);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pin_get_target(IntPtr world, PinId pin, [Out] double[] target);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pin_get_particle(IntPtr world, PinId pin, out int particle);
        // colliders
        [DllImport(Library, CallingConvention = C)] public static extern ColliderDef embra_default_collider_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_collider_create(IntPtr world, ref ColliderDef def, out ColliderId collider);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_collider_destroy(IntPtr world, ColliderId collider);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_collider_set_transform(IntPtr world, ColliderId collider, double[] position, double[] rotation);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_collider_get_transform(IntPtr world, ColliderId collider, [Out] double[] position, [Out] double[] rotation);
        // stepping and reading back
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_step(IntPtr world);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_cancel(IntPtr world);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_report(IntPtr world, out StepReport report);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_group_get_report(IntPtr world, GroupId group, out GroupReport report);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_warning(IntPtr world, out Warning warning);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_positions(IntPtr world, [Out] double[] xyz, long capacity, int first, int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_velocities(IntPtr world, [Out] double[] xyz, long capacity, int first, int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_set_positions(IntPtr world, double[] xyz, int first, int count);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_set_velocities(IntPtr world, double[] xyz, int first, int count);
        // JSON scenes
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_load_json(out IntPtr world, byte[] json, long length, byte[] baseDir);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_load_file(out IntPtr world, byte[] path);
        [DllImport(Library, CallingConvention = C)] public static extern LoadOptions embra_default_load_options();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_load_json_with_options(out IntPtr world, byte[] json, long length, ref LoadOptions options);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_save_json(IntPtr world, [Out] byte[] json, long capacity, out long length);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_save_file(IntPtr world, byte[] path);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_scene_frames(IntPtr world, out long frames);
        // fields
        [DllImport(Library, CallingConvention = C)] public static extern WindDef embra_default_wind_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_wind_create(IntPtr world, ref WindDef def, out FieldId field);
        [DllImport(Library, CallingConvention = C)] public static extern PressureDef embra_default_pressure_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_pressure_create(IntPtr world, ref PressureDef def, out FieldId field);
        [DllImport(Library, CallingConvention = C)] public static extern SurfaceTensionDef embra_default_surface_tension_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_surface_tension_create(IntPtr world, ref SurfaceTensionDef def, out FieldId field);
        [DllImport(Library, CallingConvention = C)] public static extern VortexDef embra_default_vortex_def();
        [DllImport(Library, CallingConvention = C)] public static extern int embra_vortex_create(IntPtr world, ref VortexDef def, out FieldId field);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_field_destroy(IntPtr world, FieldId field);
        [DllImport(Library, CallingConvention = C)] public static extern int embra_world_get_field_count(IntPtr world, out int count);
    }
}
