// The managed side of embra: a SafeHandle owning each world, exceptions carrying the C message,
// and World, whose methods cover the whole C ABI with flat double[] / int[] arrays pinned in place
// (no per-element marshalling). Threads sharing one World take turns (a lock around each call; the
// C library refuses a second concurrent call on a world with EMBRA_ERROR_LOCKED); Cancel() takes no
// turn, so another thread can stop a long Step. Different Worlds may step on different threads (or
// tasks) at once.
using System;
using System.IO;
using System.Runtime.InteropServices;
using System.Text;

namespace Embra
{
    /// <summary>What every embra exception carries besides its .NET type.</summary>
    public interface IEmbraException
    {
        /// <summary>The embra_status (negative).</summary>
        int Status { get; }
        /// <summary>embra_status_name(Status), e.g. "EMBRA_ERROR_STALE_ID".</summary>
        string StatusName { get; }
    }

    /// <summary>EMBRA_ERROR_INVALID_ARGUMENT (and BUFFER_TOO_SMALL): NULL, out of range, non-finite, wrong count.</summary>
    public class EmbraArgumentException : ArgumentException, IEmbraException
    {
        public EmbraArgumentException(int status, string message) : base(message) { Status = status; }
        public int Status { get; private set; }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>EMBRA_ERROR_SCHEMA: a JSON scene does not match its schema (the message starts with the pointer).</summary>
    public class EmbraSchemaException : FormatException, IEmbraException
    {
        public EmbraSchemaException(string message) : base(message) { }
        public int Status { get { return Embra.Status.Schema; } }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>EMBRA_ERROR_STALE_ID, VERSION and LOCKED: the call does not fit the world's state.</summary>
    public class EmbraInvalidOperationException : InvalidOperationException, IEmbraException
    {
        public EmbraInvalidOperationException(int status, string message) : base(message) { Status = status; }
        public int Status { get; private set; }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>EMBRA_ERROR_LOCKED: the world is in use by a call in progress on another thread; this call
    /// changed nothing and did not wait. A World's own methods take turns, so this comes from calls made on
    /// the same embra_world* around the World (through Native with World.Handle).</summary>
    public class EmbraLockedException : EmbraInvalidOperationException
    {
        public EmbraLockedException(string message) : base(Embra.Status.Locked, message) { }
    }

    /// <summary>EMBRA_ERROR_CANCELLED: World.Cancel() stopped the step; the world is as before that frame.</summary>
    public class EmbraCancelledException : OperationCanceledException, IEmbraException
    {
        public EmbraCancelledException(string message) : base(message) { }
        public int Status { get { return Embra.Status.Cancelled; } }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>A call on a disposed World: the C library refused its NULL world, with its message.</summary>
    public class EmbraObjectDisposedException : ObjectDisposedException, IEmbraException
    {
        public EmbraObjectDisposedException(int status, string message) : base("Embra.World", message) { Status = status; }
        public int Status { get; private set; }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>EMBRA_ERROR_NUMERICAL: the step went non-finite; the world is as before the step.</summary>
    public class EmbraNumericalException : ArithmeticException, IEmbraException
    {
        public EmbraNumericalException(string message) : base(message) { }
        public int Status { get { return Embra.Status.Numerical; } }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    /// <summary>EMBRA_ERROR_INTERNAL (a bug in embra, or out of memory) and unknown codes.</summary>
    public class EmbraException : Exception, IEmbraException
    {
        public EmbraException(int status, string message) : base(message) { Status = status; }
        public int Status { get; private set; }
        public string StatusName { get { return Errors.StatusName(Status); } }
    }

    public static class Errors
    {
        public static string LastMessage()
        {
            return Utf8(Native.embra_last_error_message());
        }

        public static string StatusName(int status)
        {
            return Utf8(Native.embra_status_name(status));
        }

        internal static string Utf8(IntPtr text)
        {
            if (text == IntPtr.Zero) return "";
            int n = 0;
            while (Marshal.ReadByte(text, n) != 0) ++n;
            var bytes = new byte[n];
            Marshal.Copy(text, bytes, 0, n);
            return Encoding.UTF8.GetString(bytes);
        }

        /// <summary>The exception for a failed status, with this thread's last C message.</summary>
        public static Exception For(int status, bool disposed = false)
        {
            string message = LastMessage();
            if (disposed) return new EmbraObjectDisposedException(status, message + " (this World was disposed)");
            switch (status)
            {
                case Status.InvalidArgument:
                case Status.BufferTooSmall:
                    return new EmbraArgumentException(status, message);
                case Status.Schema:
                    return new EmbraSchemaException(message);
                case Status.StaleId:
                case Status.Version:
                    return new EmbraInvalidOperationException(status, message);
                case Status.Locked:
                    return new EmbraLockedException(message);
                case Status.Numerical:
                    return new EmbraNumericalException(message);
                case Status.Cancelled:
                    return new EmbraCancelledException(message);
                default:
                    return new EmbraException(status, message);
            }
        }

        public static void Check(int status)
        {
            if (status != Status.Ok) throw For(status);
        }
    }

    /// <summary>Owns one embra_world*; releasing it calls embra_world_destroy exactly once.</summary>
    public sealed class WorldHandle : SafeHandle
    {
        internal WorldHandle(IntPtr world) : base(IntPtr.Zero, true) { SetHandle(world); }
        public override bool IsInvalid { get { return handle == IntPtr.Zero; } }
        protected override bool ReleaseHandle()
        {
            Native.embra_world_destroy(handle);
            return true;
        }
    }

    /// <summary>A body's id and its particles [First, First + Count).</summary>
    public struct Body
    {
        public BodyId Id;
        public int First, Count;
    }

    public static class Library
    {
        static Library()
        {
            // Header and library must agree before anything else (embra_check_abi).
            Errors.Check(Native.embra_check_abi(Native.AbiVersion));
        }

        public static void CheckAbi(int headerAbiVersion = Native.AbiVersion)
        {
            Errors.Check(Native.embra_check_abi(headerAbiVersion));
        }

        public static int Version { get { return Native.embra_version(); } }
        public static string VersionString { get { return Errors.Utf8(Native.embra_version_string()); } }
        public static int AbiVersion { get { return Native.embra_abi_version(); } }
        public static int ConstraintArity(ConstraintKind kind) { return Native.embra_constraint_arity((int)kind); }
        public static SolverDef DefaultSolverDef() { return Native.embra_default_solver_def(); }
        public static SolverDef FormFindingSolverDef() { return Native.embra_form_finding_solver_def(); }
        public static SolveDef DefaultSolveDef() { return Native.embra_default_solve_def(); }
        /// <summary>A residual kind's unit ("m", "rad", "m^3"): a ConstraintKind's number, or
        /// Residual.Pins / Residual.Contacts; null for neither.</summary>
        public static string ResidualUnit(int kind) { return Text(Native.embra_residual_unit(kind)); }
        /// <summary>Its name: the kind's scene name, "pins" or "contacts"; null for neither.</summary>
        public static string ResidualName(int kind) { return Text(Native.embra_residual_name(kind)); }
        static string Text(IntPtr text) { return text == IntPtr.Zero ? null : Errors.Utf8(text); }
        public static Material DefaultMaterial() { return Native.embra_default_material(); }
        public static BodyDef DefaultBodyDef() { return Native.embra_default_body_def(); }
        public static ColliderDef DefaultColliderDef() { return Native.embra_default_collider_def(); }
        public static PanelMeshDef DefaultPanelMeshDef() { return Native.embra_default_panel_mesh_def(); }
        public static Tolerances DefaultTolerances() { return Native.embra_default_tolerances(); }
        public static WindDef DefaultWindDef() { return Native.embra_default_wind_def(); }
        public static PressureDef DefaultPressureDef() { return Native.embra_default_pressure_def(); }
        public static SurfaceTensionDef DefaultSurfaceTensionDef() { return Native.embra_default_surface_tension_def(); }
        public static VortexDef DefaultVortexDef() { return Native.embra_default_vortex_def(); }
        internal static void Touch() { }
    }

    /// <summary>An embra world. Dispose it (using) to destroy it; a disposed World refuses every call
    /// with an ObjectDisposedException carrying the C library's message.</summary>
    public sealed unsafe class World : IDisposable
    {
        readonly WorldHandle handle;

        World(IntPtr world) { handle = new WorldHandle(world); }

        /// <summary>A world with the given solver settings (default: embra_default_solver_def()).</summary>
        public World(SolverDef? solver = null)
        {
            Library.Touch();
            SolverDef def = solver ?? Native.embra_default_solver_def();
            IntPtr world;
            Errors.Check(Native.embra_world_create(out world, ref def));
            handle = new WorldHandle(world);
        }

        /// <summary>A world from scene JSON text. Its OBJ paths are relative to baseDir (null: the current
        /// folder) and must stay inside it, unless allowPathsOutsideBase (for scenes the host trusts:
        /// absolute paths and ".." allowed).</summary>
        public static World LoadJson(string json, string baseDir = null, bool allowPathsOutsideBase = false)
        {
            Library.Touch();
            if (json == null) throw new ArgumentNullException("json");
            return LoadJson(Encoding.UTF8.GetBytes(json), baseDir, allowPathsOutsideBase);
        }

        static World LoadJson(byte[] text, string baseDir, bool allowPathsOutsideBase)
        {
            var options = Native.embra_default_load_options();
            options.AllowPathsOutsideBase = allowPathsOutsideBase ? 1 : 0;
            byte[] dir = CString(baseDir);
            IntPtr world;
            fixed (byte* d = dir)
            {
                options.BaseDir = (IntPtr)d;  // null when baseDir is
                Errors.Check(Native.embra_world_load_json_with_options(out world, text, text.LongLength, ref options));
            }
            return new World(world);
        }

        /// <summary>A world from a scene file. Its OBJ paths are relative to the file's folder and must stay
        /// inside it, unless allowPathsOutsideBase (as for LoadJson).</summary>
        public static World LoadFile(string path, bool allowPathsOutsideBase = false)
        {
            Library.Touch();
            if (allowPathsOutsideBase)
            {
                // embra_world_load_file has no options: the file is read here, its folder the base
                if (path == null) throw new ArgumentNullException("path");
                string folder = Path.GetDirectoryName(path);
                return LoadJson(File.ReadAllBytes(path), string.IsNullOrEmpty(folder) ? "." : folder, true);
            }
            IntPtr world;
            Errors.Check(Native.embra_world_load_file(out world, CString(path)));
            return new World(world);
        }

        static byte[] CString(string s)
        {
            return s == null ? null : Encoding.UTF8.GetBytes(s + "\0");
        }

        /// <summary>Destroys the world; waits for a call in progress on another thread. Idempotent.</summary>
        public void Dispose()
        {
            lock (gate) handle.Dispose();
        }
        public bool IsDisposed { get { return handle.IsClosed; } }

        /// <summary>Asks the step in progress (on another thread) to stop: that Step throws
        /// EmbraCancelledException with the world as before its frame. Callable from any thread at any
        /// time: it does not wait for the turn the step holds. A request made while no step runs stops the
        /// next frame stepped. A disposed World throws EmbraObjectDisposedException.</summary>
        public void Cancel()
        {
            bool added = false;
            try
            {
                try
                {
                    if (!handle.IsClosed) handle.DangerousAddRef(ref added);  // the world stays alive for the call
                }
                catch (ObjectDisposedException)
                {
                    // disposed between the check and the reference (Cancel takes no turn): as disposed
                }
                int status = Native.embra_world_cancel(added ? handle.DangerousGetHandle() : IntPtr.Zero);
                if (status != Status.Ok) throw Errors.For(status, !added);
            }
            finally
            {
                if (added) handle.DangerousRelease();
            }
        }
        public WorldHandle Handle { get { return handle; } }

        delegate int Fn(IntPtr world);
        readonly object gate = new object();

        /// <summary>Calls C with the world kept alive for the call; a disposed World passes NULL, which C
        /// refuses with its own message. The C library takes one thread at a time per world, so tasks
        /// sharing one World take turns here instead of racing.</summary>
        void Call(Fn fn)
        {
            lock (gate)
            {
                bool added = false;
                try
                {
                    if (!handle.IsClosed) handle.DangerousAddRef(ref added);
                    int status = fn(added ? handle.DangerousGetHandle() : IntPtr.Zero);
                    if (status != Status.Ok) throw Errors.For(status, !added);
                }
                finally
                {
                    if (added) handle.DangerousRelease();
                }
            }
        }

        static void Need(bool ok, string message)
        {
            if (!ok) throw new ArgumentException(message);
        }

        static double[] Three(double[] v, string name)
        {
            if (v == null || v.Length != 3) throw new ArgumentException(name + ": expected 3 numbers");
            return v;
        }

        // --- solver settings ------------------------------------------------------------------
        public SolverDef Solver
        {
            get { var d = new SolverDef(); Call(w => Native.embra_world_get_solver(w, out d)); return d; }
            set { var d = value; Call(w => Native.embra_world_set_solver(w, ref d)); }
        }

        public void SetGravity(double x, double y, double z)
        {
            var g = new[] { x, y, z };
            Call(w => Native.embra_world_set_gravity(w, g));
        }

        public WorldCounts Counts
        {
            get { var c = new WorldCounts(); Call(w => Native.embra_world_get_counts(w, out c)); return c; }
        }

        /// <summary>Ids of every body, in creation order (a loaded scene's order, as saved).</summary>
        public BodyId[] Bodies() { return Ids<BodyId>(Native.embra_world_get_bodies); }
        /// <summary>Ids of the live groups in creation order: the default and contact groups first.</summary>
        public GroupId[] Groups() { return Ids<GroupId>(Native.embra_world_get_groups); }
        /// <summary>Ids of the live pins, in creation order (a loaded scene's order, as saved).</summary>
        public PinId[] Pins() { return Ids<PinId>(Native.embra_world_get_pins); }
        /// <summary>Ids of the live colliders, in creation order (a loaded scene's order, as saved).</summary>
        public ColliderId[] Colliders() { return Ids<ColliderId>(Native.embra_world_get_colliders); }

        delegate int IdList<T>(IntPtr world, T[] ids, int capacity, out int count);

        // The two-call listing (ids, residuals, conflicts): the count first, then the items.
        T[] Ids<T>(IdList<T> list)
        {
            int count = 0;
            Call(w => list(w, null, 0, out count));
            var ids = new T[count];
            Call(w => list(w, ids, ids.Length, out count));
            return ids;
        }

        // --- groups -----------------------------------------------------------------------------
        public GroupId CreateGroup(int order = 0, int weight = 1)
        {
            var d = Native.embra_default_group_def();
            d.Order = order;
            d.Weight = weight;
            var g = new GroupId();
            Call(w => Native.embra_group_create(w, ref d, out g));
            return g;
        }

        public void DestroyGroup(GroupId group) { Call(w => Native.embra_group_destroy(w, group)); }
        public void SetGroupOrder(GroupId group, int order) { Call(w => Native.embra_group_set_order(w, group, order)); }
        public void SetGroupWeight(GroupId group, int weight) { Call(w => Native.embra_group_set_weight(w, group, weight)); }

        public GroupId DefaultGroup
        {
            get { var g = new GroupId(); Call(w => Native.embra_world_default_group(w, out g)); return g; }
        }

        public GroupId ContactGroup
        {
            get { var g = new GroupId(); Call(w => Native.embra_world_contact_group(w, out g)); return g; }
        }

        public GroupReport GroupReport(GroupId group)
        {
            var r = new GroupReport();
            Call(w => Native.embra_group_get_report(w, group, out r));
            return r;
        }

        /// <summary>Enables or disables a group (embra_group_set_enabled): a disabled group keeps its
        /// constraints and soft pins but is not projected, measured or diagnosed. Not the contact group.</summary>
        public void SetGroupEnabled(GroupId group, bool enabled)
        {
            Call(w => Native.embra_group_set_enabled(w, group, enabled ? 1 : 0));
        }

        public bool GroupEnabled(GroupId group)
        {
            int e = 0;
            Call(w => Native.embra_group_get_enabled(w, group, out e));
            return e == 1;
        }

        // --- bodies -----------------------------------------------------------------------------
        /// <summary>Adds a body (embra_body_create). positions: xyz per vertex; triangles, edges, tets:
        /// body-local indices, 3, 2, 4 per element; masses (kg per vertex) and uvs (2 per vertex) optional.
        /// `def` supplies the material, generate flags and groups (its pointers and counts are set here).</summary>
        public Body CreateBody(double[] positions, int[] triangles = null, int[] edges = null, int[] tets = null,
                               double[] masses = null, double[] uvs = null, BodyDef? def = null)
        {
            Need(positions != null && positions.Length % 3 == 0, "positions: a whole number of xyz triples is required");
            int n = positions.Length / 3;
            Need(triangles == null || triangles.Length % 3 == 0, "triangles: 3 indices per triangle");
            Need(edges == null || edges.Length % 2 == 0, "edges: 2 indices per edge");
            Need(tets == null || tets.Length % 4 == 0, "tets: 4 indices per tetrahedron");
            Need(masses == null || masses.Length == n, "masses: one per vertex");
            Need(uvs == null || uvs.Length == 2 * n, "uvs: two per vertex");
            BodyDef d = def ?? Native.embra_default_body_def();
            var body = new Body();
            fixed (double* p = positions, m = masses, uv = uvs)
            fixed (int* t = triangles, e = edges, k = tets)
            {
                d.VertexCount = n;
                d.Positions = (IntPtr)p;
                d.Masses = (IntPtr)m;
                d.Uvs = (IntPtr)uv;
                d.TriangleCount = triangles == null ? 0 : triangles.Length / 3;
                d.Triangles = (IntPtr)t;
                d.EdgeCount = edges == null ? 0 : edges.Length / 2;
                d.Edges = (IntPtr)e;
                d.TetCount = tets == null ? 0 : tets.Length / 4;
                d.Tets = (IntPtr)k;
                BodyId id = new BodyId();
                int first = 0;
                Call(w => Native.embra_body_create(w, ref d, out id, out first));
                body.Id = id;
                body.First = first;
                body.Count = n;
            }
            return body;
        }

        public void GetBodyParticles(BodyId body, out int first, out int count)
        {
            int f = 0, c = 0;
            Call(w => Native.embra_body_get_particles(w, body, out f, out c));
            first = f;
            count = c;
        }

        /// <summary>The body's material (embra_body_get_material).</summary>
        public Material GetMaterial(BodyId body)
        {
            var m = new Material();
            Call(w => Native.embra_body_get_material(w, body, out m));
            return m;
        }

        /// <summary>A body's material from the next step on, without a rebuild (embra_body_set_material): the
        /// compliances of what it generated, its damping, thickness and friction. Start from GetMaterial;
        /// mass and density must stay the body's own.</summary>
        public void SetMaterial(BodyId body, Material material)
        {
            Call(w => Native.embra_body_set_material(w, body, ref material));
        }

        /// <summary>The masses (kg) of a body's particles, one each, 0 = immovable (embra_body_get_masses).</summary>
        public double[] GetBodyMasses(BodyId body)
        {
            int n = 0;
            Call(w => Native.embra_body_get_masses(w, body, null, 0, out n));
            var out_ = new double[n];
            Call(w => Native.embra_body_get_masses(w, body, out_, out_.Length, out n));
            return out_;
        }

        /// <summary>Sets the masses (kg) of a body's particles from the next step on, without a rebuild
        /// (embra_body_set_masses): one per particle of the body, each 0 (immovable) or positive. A
        /// hard-pinned particle keeps following its pin. Refused, changing nothing, for a wrong count or a
        /// negative or non-finite mass.</summary>
        public void SetBodyMasses(BodyId body, double[] masses)
        {
            Call(w => Native.embra_body_set_masses(w, body, masses, masses == null ? 0 : masses.Length));
        }

        public void SetRestScale(BodyId body, double scale, double scaleU = 1.0, double scaleV = 1.0)
        {
            Call(w => Native.embra_body_set_rest_scale(w, body, scale, scaleU, scaleV));
        }

        /// <summary>A body's triangles as world particle indices, 3 per triangle.</summary>
        public int[] BodyTriangles(BodyId body)
        {
            return BodyInts(body, Native.embra_body_get_triangles);
        }

        private delegate int IntsReader(IntPtr world, BodyId body, int[] buffer, long capacity, out long count);

        /// <summary>A body's int list read by `read` (asked for its count first).</summary>
        private int[] BodyInts(BodyId body, IntsReader read)
        {
            long n = 0;
            Call(w => read(w, body, null, 0, out n));
            var out_ = new int[n];
            Call(w => read(w, body, out_, out_.LongLength, out n));
            return out_;
        }

        // --- panel meshes ----------------------------------------------------------------------
        /// <summary>Builds a Planar Offset Quad panel mesh (embra_panel_mesh_create): 8 particles per
        /// panel welded, 2 per vertex shared (def.Corners). With positions (xyz per top vertex) and quads (4 indices per quad) the mesh is theirs;
        /// without, a grid of def.GridColumns x def.GridRows square panels. `def` (default:
        /// embra_default_panel_mesh_def()) supplies the rest; its pointers and counts are set here.</summary>
        public Body CreatePanelMesh(PanelMeshDef? def = null, double[] positions = null, int[] quads = null)
        {
            Need((positions == null) == (quads == null), "positions and quads go together (neither: a grid)");
            Need(positions == null || positions.Length % 3 == 0, "positions: a whole number of xyz triples is required");
            Need(quads == null || quads.Length % 4 == 0, "quads: 4 indices per quad");
            PanelMeshDef d = def ?? Native.embra_default_panel_mesh_def();
            var body = new Body();
            fixed (double* p = positions)
            fixed (int* q = quads)
            {
                if (positions != null)
                {
                    d.VertexCount = positions.Length / 3;
                    d.Positions = (IntPtr)p;
                    d.QuadCount = quads.Length / 4;
                    d.Quads = (IntPtr)q;
                }
                BodyId id = new BodyId();
                int first = 0;
                Call(w => Native.embra_panel_mesh_create(w, ref d, out id, out first));
                body.Id = id;
                body.First = first;
                int count = 0;
                Call(w => Native.embra_body_get_particles(w, id, out first, out count));
                body.Count = count;
            }
            return body;
        }

        public int PanelCount(BodyId body)
        {
            int n = 0;
            Call(w => Native.embra_panel_mesh_get_panel_count(w, body, out n));
            return n;
        }

        /// <summary>The world particle of each panel corner (embra_panel_mesh_get_corner_particles): 8 a
        /// panel, its top corners 0-3 then its bottom corners 0-3.</summary>
        public int[] PanelCornerParticles(BodyId body)
        {
            return BodyInts(body, Native.embra_panel_mesh_get_corner_particles);
        }

        /// <summary>The fabrication tolerances the metrics are judged against (the scene's, else the defaults).</summary>
        public Tolerances Tolerances
        {
            get { var t = new Tolerances(); Call(w => Native.embra_world_get_tolerances(w, out t)); return t; }
            set { var t = value; Call(w => Native.embra_world_set_tolerances(w, ref t)); }
        }

        /// <summary>The section 4.1 metrics of a panel-mesh body at the current positions, judged against
        /// `tolerances` (default: the world's).</summary>
        public PanelMetrics PanelMetrics(BodyId body, Tolerances? tolerances = null)
        {
            Tolerances[] t = tolerances.HasValue ? new[] { tolerances.Value } : null;
            var m = new PanelMetrics();
            Call(w => Native.embra_panel_mesh_get_metrics(w, body, t, out m));
            return m;
        }

        /// <summary>The welds' error of a panel-mesh body (model units): per mesh vertex of two or more
        /// panels, the largest distance between two of its corner copies in one layer.</summary>
        public MetricSummary CornerGap(BodyId body)
        {
            var s = new MetricSummary();
            Call(w => Native.embra_panel_mesh_get_corner_gap(w, body, out s));
            return s;
        }

        /// <summary>One error value per particle of a panel-mesh body (in body order) for a
        /// colour map, into `into` when given (capacity = its length) or a new array.</summary>
        public double[] VertexErrors(BodyId body, PanelMetric metric, double[] into = null)
        {
            long n = 0;
            if (into == null)
            {
                Call(w => Native.embra_panel_mesh_get_vertex_errors(w, body, (int)metric, null, 0, out n));
                into = new double[n];
            }
            Call(w => Native.embra_panel_mesh_get_vertex_errors(w, body, (int)metric, into, into.LongLength, out n));
            return into;
        }

        /// <summary>The cut list of a panel-mesh body at the current positions, as JSON or CSV text.</summary>
        public string ExportCuts(BodyId body, CutsFormat format = CutsFormat.Json)
        {
            long n = 0;
            Call(w => Native.embra_panel_mesh_export_cuts(w, body, (int)format, null, 0, out n));
            var text = new byte[n];
            Call(w => Native.embra_panel_mesh_export_cuts(w, body, (int)format, text, text.LongLength, out n));
            return Encoding.UTF8.GetString(text, 0, (int)n - 1);
        }

        // --- constraints ------------------------------------------------------------------------
        /// <summary>One constraint; rest null measures it from the current positions.</summary>
        public void AddConstraint(ConstraintKind kind, int[] particles, double? rest = null, double compliance = 0.0,
                                  GroupId group = default(GroupId))
        {
            int arity = Native.embra_constraint_arity((int)kind);
            Need(particles != null && particles.Length <= 4 && (arity == 0 || particles.Length == arity),
                 "particles: kind " + kind + " takes " + arity + " particles");
            var def = Native.embra_default_constraint_def();  // filled on the stack (fixed buffer), then captured
            def.Kind = (int)kind;
            def.Group = group;
            for (int i = 0; i < particles.Length; ++i) def.Particles[i] = particles[i];
            if (rest.HasValue)
            {
                def.RestFromCurrent = 0;
                def.Rest = rest.Value;
            }
            def.Compliance = compliance;
            var d = def;
            Call(w => Native.embra_constraint_add(w, ref d));
        }

        /// <summary>Many constraints of one kind at once, all or none: particles holds arity indices per
        /// constraint; rest and compliances one value per constraint, or null.</summary>
        public int AddConstraints(ConstraintKind kind, int[] particles, double[] rest = null, double[] compliances = null,
                                  double compliance = 0.0, GroupId group = default(GroupId))
        {
            int arity = Native.embra_constraint_arity((int)kind);
            Need(particles != null && (arity == 0 || particles.Length % arity == 0),
                 "particles: a whole number of " + arity + "-tuples is required");
            int count = arity == 0 ? particles.Length : particles.Length / arity;
            Need(rest == null || rest.Length == count, "rest: one value per constraint");
            Need(compliances == null || compliances.Length == count, "compliances: one value per constraint");
            var d = Native.embra_default_constraint_batch_def();
            d.Kind = (int)kind;
            d.Group = group;
            d.Count = count;
            d.Compliance = compliance;
            fixed (int* p = particles)
            fixed (double* r = rest, c = compliances)
            {
                d.Particles = (IntPtr)p;
                d.Rest = (IntPtr)r;
                d.Compliances = (IntPtr)c;
                Call(w => Native.embra_constraints_add(w, ref d));
            }
            return count;
        }

        /// <summary>Holds a polygon of four or more corners (particle indices in order round it) in one
        /// plane (embra_polygon_planarity_add): planarity constraints of rest 0 on its windows of four
        /// consecutive corners, all of them cyclically for more than four. Returns how many were added.</summary>
        public int AddPolygonPlanarity(int[] particles, double compliance = 0.0, GroupId group = default(GroupId))
        {
            Need(particles != null, "particles: required");
            int added = 0;
            Call(w => Native.embra_polygon_planarity_add(w, group, particles, particles.Length, compliance, out added));
            return added;
        }

        /// <summary>Keeps three or more points (particle indices) in their current shape, moving as one
        /// rigid body (embra_rigid_set_add): bracing by distance constraints to a base of three or four of
        /// them, with the base's volume (solid) or each point's offset from its plane (flat). Returns how
        /// many constraints were added (4 n - 9).</summary>
        public int AddRigidSet(int[] particles, double compliance = 0.0, GroupId group = default(GroupId))
        {
            Need(particles != null, "particles: required");
            int added = 0;
            Call(w => Native.embra_rigid_set_add(w, group, particles, particles.Length, compliance, out added));
            return added;
        }

        /// <summary>Shape matching (embra_shape_match_add): three or more points (particle indices), not
        /// on one line, pulled every projection toward the best-fit rigid placement (mass-weighted, proper
        /// rotation) of their current shape; compliance in m/N (0 = hard). Returns its index among the
        /// group's shape matches.</summary>
        public int AddShapeMatch(int[] particles, double compliance = 0.0, GroupId group = default(GroupId))
        {
            Need(particles != null, "particles: required");
            int index = 0;
            Call(w => Native.embra_shape_match_add(w, group, particles, particles.Length, compliance, out index));
            return index;
        }

        /// <summary>Removes shape match `index` of the group (embra_shape_match_remove).</summary>
        public void RemoveShapeMatch(int index, GroupId group = default(GroupId))
        {
            Call(w => Native.embra_shape_match_remove(w, group, index));
        }

        /// <summary>How many shape matches the group holds (embra_group_get_shape_match_count).</summary>
        public int ShapeMatchCount(GroupId group = default(GroupId))
        {
            int count = 0;
            Call(w => Native.embra_group_get_shape_match_count(w, group, out count));
            return count;
        }

        // Edits of one constraint, named as the diagnostics name it: group (default: the default group),
        // kind and index among the group's constraints of that kind (those bodies generated first, then the
        // added ones in the order added). Only added constraints are edited; a body's follow its material.

        /// <summary>The group's constraints of `kind`, and how many of them bodies generated.</summary>
        public void ConstraintCount(GroupId group, ConstraintKind kind, out int count, out int generated)
        {
            int n = 0, g = 0;
            Call(w => Native.embra_group_get_constraint_count(w, group, (int)kind, out n, out g));
            count = n;
            generated = g;
        }

        /// <summary>One constraint as AddConstraint takes it (rest given, RestFromCurrent 0).</summary>
        public ConstraintDef Constraint(GroupId group, ConstraintKind kind, int index)
        {
            var d = new ConstraintDef();
            Call(w => Native.embra_constraint_get(w, group, (int)kind, index, out d));
            return d;
        }

        public void SetConstraintCompliance(GroupId group, ConstraintKind kind, int index, double compliance)
        {
            Call(w => Native.embra_constraint_set_compliance(w, group, (int)kind, index, compliance));
        }

        public void SetConstraintRest(GroupId group, ConstraintKind kind, int index, double rest)
        {
            Call(w => Native.embra_constraint_set_rest(w, group, (int)kind, index, rest));
        }

        /// <summary>Plasticity and rupture of an added distance or dihedral
        /// (embra_constraint_set_plasticity): past `yieldStrain` its rest follows it, past `rupture` it
        /// breaks (see Broken()); 0: never.</summary>
        public void SetConstraintPlasticity(GroupId group, ConstraintKind kind, int index, double yieldStrain,
                                            double rupture)
        {
            Call(w => Native.embra_constraint_set_plasticity(w, group, (int)kind, index, yieldStrain, rupture));
        }

        /// <summary>(yield, rupture) of a constraint (embra_constraint_get_plasticity); 0 is none.</summary>
        public (double Yield, double Rupture) ConstraintPlasticity(GroupId group, ConstraintKind kind, int index)
        {
            double y = 0, r = 0;
            Call(w => Native.embra_constraint_get_plasticity(w, group, (int)kind, index, out y, out r));
            return (y, r);
        }

        /// <summary>The constraints broken since the last call (embra_world_get_broken), in the order
        /// they broke; the world's list is emptied.</summary>
        public BrokenConstraint[] Broken() { return Ids<BrokenConstraint>(Native.embra_world_get_broken); }

        /// <summary>Moves the constraint to the end of group `to`'s; returns its index there.</summary>
        public int SetConstraintGroup(GroupId group, ConstraintKind kind, int index, GroupId to)
        {
            int at = 0;
            Call(w => Native.embra_constraint_set_group(w, group, (int)kind, index, to, out at));
            return at;
        }

        /// <summary>Removes the constraint; those after it in its group move down by one.</summary>
        public void RemoveConstraint(GroupId group, ConstraintKind kind, int index)
        {
            Call(w => Native.embra_constraint_remove(w, group, (int)kind, index));
        }

        // --- pins -------------------------------------------------------------------------------
        /// <summary>Holds a particle at target (m): compliance 0 = hard, > 0 (m/N) a soft pin in group.</summary>
        /// <summary>A frictionless sliding support (embra_support_create): `particle` held on the plane
        /// through `target` (m) normal to `axis` (PinSupport.Plane) or on the line through it along `axis`
        /// (PinSupport.Line); or a per-axis anchor (PinSupport.Axes, a roller): the world coordinates whose
        /// `axis` component is 1 held at the target's, those with 0 free ({0, 0, 1}: z held); axis null =
        /// {0, 0, 1}; compliance 0 hard, > 0 m/N; projected in `group`.</summary>
        public PinId CreateSupport(int particle, double[] target, PinSupport support = PinSupport.Plane, double[] axis = null,
                                   double compliance = 0.0, GroupId group = default(GroupId))
        {
            Three(target, "target");
            if (axis != null) Three(axis, "axis");
            var def = Native.embra_default_support_def();  // filled while on the stack (fixed buffers), then captured
            def.Particle = particle;
            def.Support = (int)support;
            for (int i = 0; i < 3; ++i) def.Target[i] = target[i];
            if (axis != null)
                for (int i = 0; i < 3; ++i) def.Axis[i] = axis[i];
            def.Compliance = compliance;
            def.Group = group;
            var d = def;
            var pin = new PinId();
            Call(w => Native.embra_support_create(w, ref d, out pin));
            return pin;
        }

        /// <summary>A frictionless support on a polyline (embra_polyline_support_create): the particle held
        /// on the closest point of the polyline through `points` (xyz per point, m, offsets from `target`,
        /// so SetPinTarget moves the curve); `closed` joins its ends. Compliance 0 = hard, else m/N.</summary>
        public PinId CreatePolylineSupport(int particle, double[] points, double[] target = null, bool closed = false,
                                           double compliance = 0.0, GroupId group = default(GroupId))
        {
            Need(points != null && points.Length % 3 == 0, "points: a whole number of xyz triples is required");
            if (target != null) Three(target, "target");
            var def = Native.embra_default_polyline_support_def();
            def.Particle = particle;
            if (target != null)
                for (int i = 0; i < 3; ++i) def.Target[i] = target[i];
            def.Closed = closed ? 1 : 0;
            def.Compliance = compliance;
            def.Group = group;
            var pin = new PinId();
            fixed (double* p = points)
            {
                def.Points = (IntPtr)p;
                def.PointCount = points.Length / 3;
                var d = def;
                Call(w => Native.embra_polyline_support_create(w, ref d, out pin));
            }
            return pin;
        }

        /// <summary>A frictionless support on a triangle mesh (embra_mesh_support_create): the particle held
        /// on the closest point of the mesh (`vertices` xyz per vertex, m, offsets from `target`, so
        /// SetPinTarget moves the mesh; `triangles` three 0-based indices each). Compliance 0 = hard, else
        /// m/N.</summary>
        public PinId CreateMeshSupport(int particle, double[] vertices, int[] triangles, double[] target = null,
                                       double compliance = 0.0, GroupId group = default(GroupId))
        {
            Need(vertices != null && vertices.Length % 3 == 0, "vertices: a whole number of xyz triples is required");
            Need(triangles != null && triangles.Length % 3 == 0, "triangles: a whole number of index triples is required");
            if (target != null) Three(target, "target");
            var def = Native.embra_default_mesh_support_def();
            def.Particle = particle;
            if (target != null)
                for (int i = 0; i < 3; ++i) def.Target[i] = target[i];
            def.Compliance = compliance;
            def.Group = group;
            var pin = new PinId();
            fixed (double* v = vertices)
            fixed (int* t = triangles)
            {
                def.Vertices = (IntPtr)v;
                def.VertexCount = vertices.Length / 3;
                def.Triangles = (IntPtr)t;
                def.TriangleCount = triangles.Length / 3;
                var d = def;
                Call(w => Native.embra_mesh_support_create(w, ref d, out pin));
            }
            return pin;
        }

        public PinId CreatePin(int particle, double[] target, double compliance = 0.0, GroupId group = default(GroupId))
        {
            Three(target, "target");
            var def = Native.embra_default_pin_def();  // filled while on the stack (fixed buffer), then captured
            def.Particle = particle;
            for (int i = 0; i < 3; ++i) def.Target[i] = target[i];
            def.Compliance = compliance;
            def.Group = group;
            var d = def;
            var pin = new PinId();
            Call(w => Native.embra_pin_create(w, ref d, out pin));
            return pin;
        }

        public void DestroyPin(PinId pin) { Call(w => Native.embra_pin_destroy(w, pin)); }

        /// <summary>A polyline support's points as created (embra_polyline_support_get_points): xyz per
        /// point, m, offsets from its target; SetPinTarget moves the target, not these, so the curve's
        /// world points are PinTarget(pin) plus each. Refused for a pin that is not one.</summary>
        public double[] PolylineSupportPoints(PinId pin)
        {
            int n = 0;
            Call(w => Native.embra_polyline_support_get_points(w, pin, null, 0, out n));
            var out_ = new double[3 * n];
            Call(w => Native.embra_polyline_support_get_points(w, pin, out_, n, out n));
            return out_;
        }

        public void SetPinTarget(PinId pin, double[] target)
        {
            Three(target, "target");
            Call(w => Native.embra_pin_set_target(w, pin, target));
        }

        public double[] PinTarget(PinId pin)
        {
            var t = new double[3];
            Call(w => Native.embra_pin_get_target(w, pin, t));
            return t;
        }

        public int PinParticle(PinId pin)
        {
            int p = -1;
            Call(w => Native.embra_pin_get_particle(w, pin, out p));
            return p;
        }

        // --- colliders --------------------------------------------------------------------------
        /// <summary>A collider from a def (from Native.embra_default_collider_def(), fields set), with
        /// the local vertices (and triangles) of a convex or mesh shape.</summary>
        public ColliderId CreateCollider(ColliderDef def, double[] vertices = null, int[] triangles = null)
        {
            Need(vertices == null || vertices.Length % 3 == 0, "vertices: a whole number of xyz triples is required");
            Need(triangles == null || triangles.Length % 3 == 0, "triangles: 3 indices per triangle");
            var c = new ColliderId();
            fixed (double* v = vertices)
            fixed (int* t = triangles)
            {
                if (vertices != null)
                {
                    def.Vertices = (IntPtr)v;
                    def.VertexCount = vertices.Length / 3;
                }
                if (triangles != null)
                {
                    def.Triangles = (IntPtr)t;
                    def.TriangleCount = triangles.Length / 3;
                }
                Call(w => Native.embra_collider_create(w, ref def, out c));
            }
            return c;
        }

        public void DestroyCollider(ColliderId collider) { Call(w => Native.embra_collider_destroy(w, collider)); }

        public void SetColliderTransform(ColliderId collider, double[] position, double[] rotation)
        {
            Three(position, "position");
            Need(rotation != null && rotation.Length == 4, "rotation: a quaternion {w, x, y, z}");
            Call(w => Native.embra_collider_set_transform(w, collider, position, rotation));
        }

        /// <summary>Where the collider is now (scene actions included): position and rotation {w, x, y, z}.</summary>
        public void ColliderTransform(ColliderId collider, out double[] position, out double[] rotation)
        {
            var p = new double[3];
            var q = new double[4];
            Call(w => Native.embra_collider_get_transform(w, collider, p, q));
            position = p;
            rotation = q;
        }

        // --- fields -----------------------------------------------------------------------------
        /// <summary>A wind field from a def (from Library.DefaultWindDef(), fields set); Body {0,0} =
        /// every body.</summary>
        public FieldId CreateWind(WindDef def)
        {
            var f = new FieldId();
            Call(w => Native.embra_wind_create(w, ref def, out f));
            return f;
        }

        /// <summary>Air pressure on a closed body and, with KeepVolume 1, its volume held (def from
        /// Library.DefaultPressureDef(); Body is required).</summary>
        public FieldId CreatePressure(PressureDef def)
        {
            var f = new FieldId();
            Call(w => Native.embra_pressure_create(w, ref def, out f));
            return f;
        }

        /// <summary>A soap-film tension on a body's triangles (def from Library.DefaultSurfaceTensionDef();
        /// Body is required).</summary>
        public FieldId CreateSurfaceTension(SurfaceTensionDef def)
        {
            var f = new FieldId();
            Call(w => Native.embra_surface_tension_create(w, ref def, out f));
            return f;
        }

        /// <summary>A decaying torsion field about an axis (def from Library.DefaultVortexDef()); Body
        /// {0,0} = every particle.</summary>
        public FieldId CreateVortex(VortexDef def)
        {
            var f = new FieldId();
            Call(w => Native.embra_vortex_create(w, ref def, out f));
            return f;
        }

        /// <summary>A field's parameters, read back and changed between steps (embra_*_get, embra_*_set): the
        /// kind and body stay those it was created with.</summary>
        public WindDef GetWind(FieldId field) { var d = new WindDef(); Call(w => Native.embra_wind_get(w, field, out d)); return d; }
        public void SetWind(FieldId field, WindDef def) { Call(w => Native.embra_wind_set(w, field, ref def)); }
        public PressureDef GetPressure(FieldId field) { var d = new PressureDef(); Call(w => Native.embra_pressure_get(w, field, out d)); return d; }
        public void SetPressure(FieldId field, PressureDef def) { Call(w => Native.embra_pressure_set(w, field, ref def)); }
        public SurfaceTensionDef GetSurfaceTension(FieldId field)
        {
            var d = new SurfaceTensionDef();
            Call(w => Native.embra_surface_tension_get(w, field, out d));
            return d;
        }
        public void SetSurfaceTension(FieldId field, SurfaceTensionDef def)
        {
            Call(w => Native.embra_surface_tension_set(w, field, ref def));
        }
        public VortexDef GetVortex(FieldId field) { var d = new VortexDef(); Call(w => Native.embra_vortex_get(w, field, out d)); return d; }
        public void SetVortex(FieldId field, VortexDef def) { Call(w => Native.embra_vortex_set(w, field, ref def)); }

        /// <summary>Destroys a field; its id becomes stale.</summary>
        public void DestroyField(FieldId field) { Call(w => Native.embra_field_destroy(w, field)); }

        /// <summary>The number of live fields.</summary>
        public int FieldCount
        {
            get { int n = 0; Call(w => Native.embra_world_get_field_count(w, out n)); return n; }
        }

        // --- stepping and reading back ----------------------------------------------------------
        /// <summary>Advances frames. EmbraNumericalException, or EmbraCancelledException (Cancel() from
        /// another thread): the world is as before the failing frame; the frames before it stay stepped.</summary>
        public void Step(int frames = 1)
        {
            for (int i = 0; i < frames; ++i) Call(Native.embra_world_step);
        }

        /// <summary>
        /// Steps until the world is at rest (SolveUntil.Settled) and, with SolveUntil.Tolerance, every
        /// panel mesh within its tolerance targets and every kind's constraint residual within its
        /// residual target, or def.MaxFrames frames or def.MaxSeconds of wall time have passed
        /// (embra_world_solve; def null: Library.DefaultSolveDef()). The result says why it stopped:
        /// Outcome (a Solve value), Frames, Period (s, of an oscillation) and the worst metric
        /// (WorstMetric a PanelMetric, EMBRA_SOLVE_WORST_RESIDUAL (16) for a kind's residual above its
        /// target with WorstElement the kind, or -1 without a panel mesh and with every residual within
        /// its target; WorstBody, WorstElement, WorstLayer 0 top / 1 bottom / -1, WorstValue,
        /// WorstTarget).
        /// </summary>
        public SolveResult Solve(SolveDef? def = null)
        {
            SolveDef d = def ?? Native.embra_default_solve_def();
            var r = new SolveResult();
            Call(w => Native.embra_world_solve(w, ref d, out r));
            return r;
        }

        /// <summary>Solve with the defaults but for `until` and the frame budget.</summary>
        public SolveResult Solve(SolveUntil until, int maxFrames = 1000)
        {
            SolveDef d = Native.embra_default_solve_def();
            d.Until = (int)until;
            d.MaxFrames = maxFrames;
            return Solve(d);
        }

        /// <summary>The last step's residuals by kind, each in its own unit (Library.ResidualUnit):
        /// every kind the world holds, in kind order, then pins, then contacts.</summary>
        public KindResidual[] Residuals() { return Ids<KindResidual>(Native.embra_world_get_residuals); }

        /// <summary>The `count` constraints and soft pins of the last step that fight hardest, worst
        /// first, ranked by Violation x Force (an energy for every kind; embra_world_get_worst_constraints).
        /// Kind is a ConstraintKind's number or Residual.Pins; Index the constraint's place among its
        /// group's constraints of that kind, as added (-1 for a pin); Force in N (N m for angles).</summary>
        public ConstraintResidual[] WorstConstraints(int count = 10)
        {
            Need(count >= 0, "count: must be >= 0");
            var res = new ConstraintResidual[count];
            int n = 0;
            Call(w => Native.embra_world_get_worst_constraints(w, res, res.Length, out n));
            Array.Resize(ref res, n);
            return res;
        }

        /// <summary>Pairs of groups whose forces on shared particles oppose in the last step, largest
        /// first (embra_world_get_group_conflicts): A before B in the projection order, Force in N.</summary>
        public GroupConflict[] GroupConflicts() { return Ids<GroupConflict>(Native.embra_world_get_group_conflicts); }

        /// <summary>The residual of every constraint of `kind` in `group` after the last step, in the
        /// order they were added, in the kind's unit (embra_group_get_residuals).</summary>
        public double[] GroupResiduals(GroupId group, ConstraintKind kind)
        {
            return PerConstraint(Native.embra_group_get_residuals, group, kind);
        }

        /// <summary>The force of every constraint of `kind` in `group` after the last step, in the order
        /// they were added (embra_group_get_forces): -lambda / h^2 of the last substep; for a distance or
        /// tether its tension in N (positive pulling its ends together).</summary>
        public double[] ConstraintForces(GroupId group, ConstraintKind kind)
        {
            return PerConstraint(Native.embra_group_get_forces, group, kind);
        }

        delegate int PerConstraintList(IntPtr world, GroupId group, int kind, double[] buffer, long capacity, out long count);

        // One value per constraint of `kind` in `group`, through a two-call listing.
        double[] PerConstraint(PerConstraintList list, GroupId group, ConstraintKind kind)
        {
            long n = 0;
            Call(w => list(w, group, (int)kind, null, 0, out n));
            var values = new double[n];
            Call(w => list(w, group, (int)kind, values, values.LongLength, out n));
            return values;
        }

        /// <summary>The force (N) every live pin exerts on its particle after the last step
        /// (embra_world_get_reactions), pins in creation-slot order: at a static rest they sum to minus
        /// the weights and point loads.</summary>
        public Reaction[] Reactions() { return Ids<Reaction>(Native.embra_world_get_reactions); }

        /// <summary>The force (N) every live collider exerts on the world after the last step, from its
        /// contacts of the last substep, normal push and friction (embra_world_get_collider_reactions),
        /// colliders in creation-slot order: Force in N, Moment in N m about the collider's position. At a
        /// static rest they and the pins' reactions sum to minus the weights and loads.</summary>
        public ColliderReaction[] ColliderReactions() { return Ids<ColliderReaction>(Native.embra_world_get_collider_reactions); }

        public StepReport Report
        {
            get { var r = new StepReport(); Call(w => Native.embra_world_get_report(w, out r)); return r; }
        }

        public Warning Warning
        {
            get { var r = new Warning(); Call(w => Native.embra_world_get_warning(w, out r)); return r; }
        }

        /// <summary>Positions (m) of particles [first, first + count) as xyz, into `into` when given
        /// (capacity = its length) or a new array; count -1 = to the last particle.</summary>
        public double[] GetPositions(int first = 0, int count = -1, double[] into = null)
        {
            return Read(Native.embra_world_get_positions, first, count, into);
        }

        public double[] GetVelocities(int first = 0, int count = -1, double[] into = null)
        {
            return Read(Native.embra_world_get_velocities, first, count, into);
        }

        delegate int ReadFn(IntPtr world, double[] xyz, long capacity, int first, int count);

        double[] Read(ReadFn fn, int first, int count, double[] into)
        {
            if (count == -1) count = Math.Max(Counts.Particles - first, 0);
            double[] xyz = into ?? new double[3 * (long)Math.Max(count, 0)];
            Call(w => fn(w, xyz, xyz.LongLength, first, count));
            return xyz;
        }

        /// <summary>Moves particles [first, first + xyz.Length / 3) to xyz (m); velocities are kept.</summary>
        public void SetPositions(double[] xyz, int first = 0)
        {
            Need(xyz != null && xyz.Length % 3 == 0, "xyz: a whole number of xyz triples is required");
            Call(w => Native.embra_world_set_positions(w, xyz, first, xyz.Length / 3));
        }

        public void SetVelocities(double[] xyz, int first = 0)
        {
            Need(xyz != null && xyz.Length % 3 == 0, "xyz: a whole number of xyz triples is required");
            Call(w => Native.embra_world_set_velocities(w, xyz, first, xyz.Length / 3));
        }

        /// <summary>Point loads (N) of particles [first, first + count), as GetPositions.</summary>
        public double[] GetLoads(int first = 0, int count = -1, double[] into = null)
        {
            return Read(Native.embra_world_get_loads, first, count, into);
        }

        /// <summary>Sets point loads (N, xyz per particle) on particles [first, first + xyz.Length / 3):
        /// forces applied every substep beside gravity until set again.</summary>
        public void SetLoads(double[] xyz, int first = 0)
        {
            Need(xyz != null && xyz.Length % 3 == 0, "xyz: a whole number of xyz triples is required");
            Call(w => Native.embra_world_set_loads(w, xyz, first, xyz.Length / 3));
        }

        /// <summary>An area load (embra_area_load) on the triangle of three distinct particles: pressure in
        /// Pa, along the triangle's normal (AreaLoadMode.Normal) or along `direction` per true or per
        /// projected area (TrueArea, ProjectedArea; the direction of any nonzero length).</summary>
        public static AreaLoad MakeAreaLoad(int a, int b, int c, double pressure, AreaLoadMode mode = AreaLoadMode.Normal,
                                            double[] direction = null)
        {
            Need(direction == null || direction.Length == 3, "direction: 3 numbers are required");
            var l = new AreaLoad { Mode = (int)mode, Pressure = pressure };
            l.Particles[0] = a;
            l.Particles[1] = b;
            l.Particles[2] = c;
            for (int k = 0; k < 3; ++k) l.Direction[k] = direction == null ? (k == 2 ? -1.0 : 0.0) : direction[k];
            return l;
        }

        /// <summary>A line load (embra_line_load): `load` N per m of the edge between two distinct particles.</summary>
        public static LineLoad MakeLineLoad(int a, int b, double[] load)
        {
            Need(load != null && load.Length == 3, "load: 3 numbers are required");
            var l = new LineLoad();
            l.Particles[0] = a;
            l.Particles[1] = b;
            for (int k = 0; k < 3; ++k) l.Load[k] = load[k];
            return l;
        }

        /// <summary>Replaces the area loads (embra_world_set_area_loads): a third of each triangle's force
        /// on each corner, every substep beside gravity, until set again; an empty array removes them.
        /// Refused, changing nothing, as the C ABI refuses.</summary>
        public void SetAreaLoads(AreaLoad[] loads)
        {
            Need(loads != null, "loads: an array is required");
            Call(w => Native.embra_world_set_area_loads(w, loads, loads.Length));
        }

        /// <summary>The area loads as set.</summary>
        public AreaLoad[] AreaLoads() { return Ids<AreaLoad>(Native.embra_world_get_area_loads); }

        /// <summary>Replaces the line loads (embra_world_set_line_loads): half of each edge's force on each
        /// end, every substep beside gravity, until set again.</summary>
        public void SetLineLoads(LineLoad[] loads)
        {
            Need(loads != null, "loads: an array is required");
            Call(w => Native.embra_world_set_line_loads(w, loads, loads.Length));
        }

        /// <summary>The line loads as set.</summary>
        public LineLoad[] LineLoads() { return Ids<LineLoad>(Native.embra_world_get_line_loads); }

        // --- JSON scenes ------------------------------------------------------------------------
        public string SaveJson() { return Text(Native.embra_world_save_json); }

        delegate int TextListing(IntPtr world, byte[] buffer, long capacity, out long length);

        // A NUL-terminated UTF-8 text through a two-call listing (the length counts the NUL).
        string Text(TextListing write)
        {
            long n = 0;
            Call(w => write(w, null, 0, out n));
            var text = new byte[n];
            Call(w => write(w, text, text.LongLength, out n));
            return Encoding.UTF8.GetString(text, 0, (int)n - 1);
        }

        public void SaveFile(string path)
        {
            byte[] p = CString(path);
            Call(w => Native.embra_world_save_file(w, p));
        }

        // --- OBJ -------------------------------------------------------------------------------
        /// <summary>The world as Wavefront OBJ text (embra_world_export_obj): every particle a `v` line in
        /// world order, each body's triangles as `f` lines, a body without triangles (a hanging net) as `l`
        /// lines of its edges.</summary>
        public string ExportObj() { return Text(Native.embra_world_export_obj); }

        /// <summary>Writes ExportObj()'s text to a file (replaced whole; no partial file on failure).</summary>
        public void WriteObj(string path)
        {
            byte[] p = CString(path);
            Call(w => Native.embra_world_write_obj(w, p));
        }

        public long SceneFrames
        {
            get { long f = 0; Call(w => Native.embra_world_get_scene_frames(w, out f)); return f; }
        }
    }
}
