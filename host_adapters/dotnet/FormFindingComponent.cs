// A Grasshopper-style component over embra, with no Rhino dependency: the shapes of GH_Component
// (RegisterInputParams / RegisterOutputParams / SolveInstance(IGH_DataAccess)) and of its data
// (Point3d, MeshFace) are mirrored here so the class reads, and is wired, as a Grasshopper author
// would write it; a Rhino build replaces this file's small base types with Grasshopper's own.
using System;
using System.Collections;
using System.Collections.Generic;
using System.Linq;

namespace Embra.Grasshopper
{
    public struct Point3d : IPoint3d
    {
        public double X, Y, Z;
        public Point3d(double x, double y, double z) { X = x; Y = y; Z = z; }
        double IPoint3d.X { get { return X; } }
        double IPoint3d.Y { get { return Y; } }
        double IPoint3d.Z { get { return Z; } }
        public double DistanceTo(Point3d o)
        {
            double dx = X - o.X, dy = Y - o.Y, dz = Z - o.Z;
            return Math.Sqrt(dx * dx + dy * dy + dz * dz);
        }
        public override string ToString() { return "{" + X + ", " + Y + ", " + Z + "}"; }
    }

    /// <summary>A mesh face as Rhino stores it: a triangle has C == D.</summary>
    public struct MeshFace
    {
        public int A, B, C, D;
        public MeshFace(int a, int b, int c) { A = a; B = b; C = c; D = c; }
        public MeshFace(int a, int b, int c, int d) { A = a; B = b; C = c; D = d; }
        public bool IsQuad { get { return C != D; } }
    }

    /// <summary>A point as a host hands it: the real plugin wraps Rhino.Geometry.Point3d (a struct
    /// with X, Y, Z) in this; Point3d above implements it.</summary>
    public interface IPoint3d
    {
        double X { get; }
        double Y { get; }
        double Z { get; }
    }

    /// <summary>A mesh as a host hands it: vertices and faces (Rhino's Mesh.Vertices and Mesh.Faces,
    /// a triangle with C == D). The real plugin wraps Rhino.Geometry.Mesh in this and turns the
    /// component's output mesh back into one (Mesh.Vertices.Add, Mesh.Faces.AddFace).</summary>
    public interface IMeshLike
    {
        IReadOnlyList<IPoint3d> Vertices { get; }
        IReadOnlyList<MeshFace> Faces { get; }
    }

    /// <summary>A mesh held in lists: what the component outputs, and what a host without Rhino passes.</summary>
    public sealed class ListMesh : IMeshLike
    {
        readonly List<IPoint3d> vertices;
        readonly List<MeshFace> faces;
        public ListMesh(IEnumerable<IPoint3d> vertices, IEnumerable<MeshFace> faces)
        {
            this.vertices = vertices.ToList();
            this.faces = faces.ToList();
        }
        public IReadOnlyList<IPoint3d> Vertices { get { return vertices; } }
        public IReadOnlyList<MeshFace> Faces { get { return faces; } }
    }

    /// <summary>What keeps a running component stepping: Grasshopper's
    /// GH_Document.ScheduleSolution(interval, callback) in the plugin, the callback expiring the
    /// component so the canvas solves it again; a test drives it by hand.</summary>
    public interface ISolutionScheduler
    {
        void ScheduleSolution(int intervalMs, Action expire);
    }

    public enum GH_ParamAccess { item, list }
    public enum GH_RuntimeMessageLevel { Remark, Warning, Error }

    public sealed class Param
    {
        public string Name, NickName, Description;
        public GH_ParamAccess Access;
        public bool Optional;
    }

    public sealed class ParamList : List<Param>
    {
        public void Add(string name, string nickName, string description, GH_ParamAccess access, bool optional = false)
        {
            Add(new Param { Name = name, NickName = nickName, Description = description, Access = access, Optional = optional });
        }
    }

    /// <summary>Grasshopper's IGH_DataAccess, the part a component uses.</summary>
    public interface IGH_DataAccess
    {
        bool GetData<T>(int index, ref T destination);
        bool GetDataList<T>(int index, List<T> list);
        bool SetData(int index, object data);
        bool SetDataList(int index, IEnumerable data);
    }

    /// <summary>Wires values to a component's inputs by index and collects its outputs (what the
    /// canvas does in Grasshopper).</summary>
    public sealed class DataAccess : IGH_DataAccess
    {
        readonly Dictionary<int, object> inputs = new Dictionary<int, object>();
        public readonly Dictionary<int, object> Outputs = new Dictionary<int, object>();

        public DataAccess Set(int index, object value)
        {
            inputs[index] = value;
            return this;
        }

        public bool GetData<T>(int index, ref T destination)
        {
            object v;
            if (!inputs.TryGetValue(index, out v) || v == null) return false;
            destination = v is T ? (T)v : (T)Convert.ChangeType(v, typeof(T), System.Globalization.CultureInfo.InvariantCulture);
            return true;
        }

        public bool GetDataList<T>(int index, List<T> list)
        {
            object v;
            if (!inputs.TryGetValue(index, out v) || v == null) return false;
            list.AddRange(((IEnumerable)v).Cast<T>());
            return true;
        }

        public bool SetData(int index, object data)
        {
            Outputs[index] = data;
            return true;
        }

        public bool SetDataList(int index, IEnumerable data)
        {
            Outputs[index] = data.Cast<object>().ToList();
            return true;
        }

        public T Get<T>(int index) { return (T)Outputs[index]; }
        public List<T> GetList<T>(int index) { return ((List<object>)Outputs[index]).Cast<T>().ToList(); }
    }

    /// <summary>GH_Component's shape: parameters registered once, SolveInstance per solution.</summary>
    public abstract class GH_Component
    {
        public readonly string Name, NickName, Description, Category, SubCategory;
        public readonly ParamList Inputs = new ParamList(), Outputs = new ParamList();
        public readonly List<KeyValuePair<GH_RuntimeMessageLevel, string>> RuntimeMessages =
            new List<KeyValuePair<GH_RuntimeMessageLevel, string>>();
        public string Message = "";

        protected GH_Component(string name, string nickName, string description, string category, string subCategory)
        {
            Name = name; NickName = nickName; Description = description; Category = category; SubCategory = subCategory;
            RegisterInputParams(Inputs);
            RegisterOutputParams(Outputs);
        }

        protected abstract void RegisterInputParams(ParamList pManager);
        protected abstract void RegisterOutputParams(ParamList pManager);
        protected abstract void SolveInstance(IGH_DataAccess DA);

        public void AddRuntimeMessage(GH_RuntimeMessageLevel level, string text)
        {
            RuntimeMessages.Add(new KeyValuePair<GH_RuntimeMessageLevel, string>(level, text));
        }

        /// <summary>Set by the canvas: marks the component for another solution (GH_Component.ExpireSolution).</summary>
        public Action SolutionExpired;

        protected void ExpireSolution()
        {
            if (SolutionExpired != null) SolutionExpired();
        }

        /// <summary>What the canvas calls when an input changes or the timer ticks.</summary>
        public void ComputeData(IGH_DataAccess DA)
        {
            RuntimeMessages.Clear();
            SolveInstance(DA);
        }
    }

    /// <summary>A goal: one constraint on the mesh's vertices, with the paper's importance weight.
    /// Goals of one weight share a group of that weight (projected that many times per pass); heavier
    /// groups go later, so they take precedence.</summary>
    public sealed class Goal
    {
        public ConstraintKind Kind;
        public int[] Vertices;
        public double? Rest;          // null: measured from the input vertices
        public double Compliance;     // 0 = hard; unit per newton of the kind (m/N for lengths)
        public int Weight = 1;        // importance weight, [1, 1000]

        public static Goal Length(int a, int b, double? rest = null, double compliance = 0, int weight = 1)
        {
            return new Goal { Kind = ConstraintKind.Distance, Vertices = new[] { a, b }, Rest = rest, Compliance = compliance, Weight = weight };
        }

        public static Goal MaxLength(int a, int b, double rest, double compliance = 0, int weight = 1)
        {
            return new Goal { Kind = ConstraintKind.Tether, Vertices = new[] { a, b }, Rest = rest, Compliance = compliance, Weight = weight };
        }

        public static Goal Weld(int a, int b, int weight = 1)
        {
            return new Goal { Kind = ConstraintKind.Weld, Vertices = new[] { a, b }, Rest = 0, Weight = weight };
        }

        public static Goal Angle(int corner, int a, int b, double? rest = null, double compliance = 0, int weight = 1)
        {
            return new Goal { Kind = ConstraintKind.EdgeAngle, Vertices = new[] { corner, a, b }, Rest = rest, Compliance = compliance, Weight = weight };
        }

        /// <summary>What the goal measures on xyz (m or rad): length, or the angle at the corner.</summary>
        public double Measure(double[] xyz, int first)
        {
            Func<int, int, double> sub = (v, c) => xyz[3 * (first + v) + c];
            if (Kind == ConstraintKind.EdgeAngle)
            {
                double ax = sub(Vertices[1], 0) - sub(Vertices[0], 0), ay = sub(Vertices[1], 1) - sub(Vertices[0], 1), az = sub(Vertices[1], 2) - sub(Vertices[0], 2);
                double bx = sub(Vertices[2], 0) - sub(Vertices[0], 0), by = sub(Vertices[2], 1) - sub(Vertices[0], 1), bz = sub(Vertices[2], 2) - sub(Vertices[0], 2);
                double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
                return Math.Atan2(Math.Sqrt(cx * cx + cy * cy + cz * cz), ax * bx + ay * by + az * bz);
            }
            double dx = sub(Vertices[1], 0) - sub(Vertices[0], 0), dy = sub(Vertices[1], 1) - sub(Vertices[0], 1), dz = sub(Vertices[1], 2) - sub(Vertices[0], 2);
            return Math.Sqrt(dx * dx + dy * dy + dz * dz);
        }

        /// <summary>How far the goal is from being met (>= 0): a tether only counts when overstretched.</summary>
        public double Error(double[] xyz, int first, double rest)
        {
            double m = Measure(xyz, first);
            return Kind == ConstraintKind.Tether ? Math.Max(m - rest, 0.0) : Math.Abs(m - rest);
        }
    }

    /// <summary>Form finding on a mesh: anchors (movable), goals with weights, gravity; Reset rebuilds
    /// the world from the inputs, Run steps it every solution and schedules the next (Scheduler), and
    /// changed gravity, mass, compliances, damping and anchors act on the running world (ApplyChanges).
    /// Outputs the mesh on its moved vertices, the vertices and the error of every goal and anchor,
    /// for colouring by fabrication tolerance.</summary>
    public sealed class FormFindingComponent : GH_Component, IDisposable
    {
        public const int InVertices = 0, InFaces = 1, InAnchors = 2, InAnchorTargets = 3, InGoals = 4, InGravity = 5,
            InMass = 6, InStretchCompliance = 7, InBendCompliance = 8, InStretchWeight = 9, InDamping = 10,
            InSubsteps = 11, InIterations = 12, InStepsPerSolve = 13, InReset = 14, InRun = 15, InMesh = 16;
        public const int OutVertices = 0, OutGoalErrors = 1, OutAnchorErrors = 2, OutResidual = 3, OutKineticEnergy = 4,
            OutSettled = 5, OutFrame = 6, OutMesh = 7;

        /// <summary>Keeps the component stepping while Run is on: after each running solution it asks
        /// for the next one IntervalMs later. Null: one step batch per solution.</summary>
        public ISolutionScheduler Scheduler;
        public int IntervalMs = 10;

        World world;
        Body body;
        PinId[] pins = new PinId[0];
        Point3d[] anchorTargets = new Point3d[0];
        List<MeshFace> faces = new List<MeshFace>();
        Point3d gravityNow;
        double stretchNow, bendNow, dampingNow, massNow;
        int[] anchors = new int[0];
        List<Goal> goals = new List<Goal>();
        double[] goalRest = new double[0];
        double[] massShares = new double[0];  // each vertex's share of the total mass, as built

        public FormFindingComponent()
            : base("Embra Form Finding", "Embra", "Finds a form under goals, anchors and gravity (XPBD)", "Embra", "Solve") { }

        protected override void RegisterInputParams(ParamList p)
        {
            p.Add("Vertices", "V", "Mesh vertices (m)", GH_ParamAccess.list);
            p.Add("Faces", "F", "Mesh faces (quads are split into two triangles)", GH_ParamAccess.list);
            p.Add("Anchors", "A", "Indices of anchored vertices", GH_ParamAccess.list, true);
            p.Add("AnchorTargets", "AT", "Where each anchor is moved to (default: where it is)", GH_ParamAccess.list, true);
            p.Add("Goals", "G", "Goals with importance weights", GH_ParamAccess.list, true);
            p.Add("Gravity", "g", "Gravity vector (m/s^2), default (0, 0, -9.81)", GH_ParamAccess.item, true);
            p.Add("Mass", "m", "Total mass (kg), default 1", GH_ParamAccess.item, true);
            p.Add("StretchCompliance", "Cs", "Edge compliance (m/N), default 0 (inextensible)", GH_ParamAccess.item, true);
            p.Add("BendCompliance", "Cb", "Bending compliance (rad/(N m)), default 1", GH_ParamAccess.item, true);
            p.Add("StretchWeight", "Ws", "Importance weight of the mesh edges, default 1", GH_ParamAccess.item, true);
            p.Add("Damping", "D", "Velocity decay (1/s), default 0", GH_ParamAccess.item, true);
            p.Add("Substeps", "S", "Substeps per frame, default 16", GH_ParamAccess.item, true);
            p.Add("Iterations", "I", "Passes per substep, default 1", GH_ParamAccess.item, true);
            p.Add("StepsPerSolve", "N", "Frames stepped per solution while running, default 1", GH_ParamAccess.item, true);
            p.Add("Reset", "R", "Rebuild from the inputs", GH_ParamAccess.item, true);
            p.Add("Run", "On", "Step while true (the component schedules its next solution)", GH_ParamAccess.item, true);
            p.Add("Mesh", "M", "The mesh to shape (instead of Vertices and Faces)", GH_ParamAccess.item, true);
        }

        protected override void RegisterOutputParams(ParamList p)
        {
            p.Add("Vertices", "V", "Vertices now (m)", GH_ParamAccess.list);
            p.Add("GoalErrors", "Eg", "Per goal: |measure - rest| (m or rad)", GH_ParamAccess.list);
            p.Add("AnchorErrors", "Ea", "Per anchor: distance to its target (m)", GH_ParamAccess.list);
            p.Add("Residual", "r", "Largest constraint residual of the last frame", GH_ParamAccess.item);
            p.Add("KineticEnergy", "K", "Kinetic energy (J)", GH_ParamAccess.item);
            p.Add("Settled", "Ok", "No vertex moves faster than 1 mm/s", GH_ParamAccess.item);
            p.Add("Frame", "f", "Frames stepped since the last reset", GH_ParamAccess.item);
            p.Add("Mesh", "M", "The input's faces on the vertices now", GH_ParamAccess.item);
        }

        static T Item<T>(IGH_DataAccess DA, int index, T fallback)
        {
            T v = fallback;
            return DA.GetData(index, ref v) ? v : fallback;
        }

        protected override void SolveInstance(IGH_DataAccess DA)
        {
            try
            {
                bool reset = Item(DA, InReset, false), run = Item(DA, InRun, false);
                if (reset || world == null) Build(DA);
                else ApplyChanges(DA);
                var targets = new List<IPoint3d>();
                if (DA.GetDataList(InAnchorTargets, targets) && targets.Count > 0)
                {
                    if (targets.Count != pins.Length)
                        throw new ArgumentException("AnchorTargets: " + targets.Count + " points for " + pins.Length + " anchors");
                    for (int k = 0; k < pins.Length; ++k)
                        world.SetPinTarget(pins[k], new[] { targets[k].X, targets[k].Y, targets[k].Z });
                    anchorTargets = targets.Select(t => new Point3d(t.X, t.Y, t.Z)).ToArray();
                }
                if (run) world.Step(Item(DA, InStepsPerSolve, 1));
                Output(DA);
                if (run && Scheduler != null) Scheduler.ScheduleSolution(IntervalMs, ExpireSolution);
            }
            catch (Exception e)
            {
                // Grasshopper shows a component's failure on the component; nothing reaches the canvas.
                AddRuntimeMessage(GH_RuntimeMessageLevel.Error, e.Message);
                Message = "error";
            }
        }

        void Build(IGH_DataAccess DA)
        {
            var vertices = new List<Point3d>();
            var faceList = new List<MeshFace>();
            var anchorList = new List<int>();
            var goalList = new List<Goal>();
            IMeshLike mesh = null;
            if (DA.GetData(InMesh, ref mesh) && mesh != null)
            {
                vertices.AddRange(mesh.Vertices.Select(v => new Point3d(v.X, v.Y, v.Z)));
                faceList.AddRange(mesh.Faces);
            }
            else
            {
                var given = new List<IPoint3d>();
                DA.GetDataList(InVertices, given);
                vertices.AddRange(given.Select(v => new Point3d(v.X, v.Y, v.Z)));
                DA.GetDataList(InFaces, faceList);
            }
            if (vertices.Count == 0) throw new ArgumentException("Vertices: none given (neither a Mesh nor Vertices)");
            DA.GetDataList(InAnchors, anchorList);
            DA.GetDataList(InGoals, goalList);
            var gravity = Item(DA, InGravity, new Point3d(0, 0, -9.81));

            var xyz = new double[3 * vertices.Count];
            for (int i = 0; i < vertices.Count; ++i)
            {
                xyz[3 * i] = vertices[i].X;
                xyz[3 * i + 1] = vertices[i].Y;
                xyz[3 * i + 2] = vertices[i].Z;
            }
            var tri = new List<int>();
            foreach (var f in faceList)
            {
                tri.AddRange(new[] { f.A, f.B, f.C });
                if (f.IsQuad) tri.AddRange(new[] { f.A, f.C, f.D });
            }

            var solver = Library.DefaultSolverDef();
            unsafe
            {
                solver.Gravity[0] = gravity.X;
                solver.Gravity[1] = gravity.Y;
                solver.Gravity[2] = gravity.Z;
            }
            solver.Damping = Item(DA, InDamping, 0.0);
            solver.Substeps = Item(DA, InSubsteps, 16);
            solver.Iterations = Item(DA, InIterations, 1);

            var next = new World(solver);  // built whole, then swapped in: a failure keeps the old world
            try
            {
                var stretch = next.CreateGroup(0, Item(DA, InStretchWeight, 1));
                var bend = next.CreateGroup(1, 1);
                var def = Native.embra_default_body_def();
                def.Material.Mass = Item(DA, InMass, 1.0);
                def.Material.StretchCompliance = Item(DA, InStretchCompliance, 0.0);
                def.Material.BendCompliance = Item(DA, InBendCompliance, 1.0);
                def.StretchGroup = stretch;
                def.BendGroup = bend;
                var b = next.CreateBody(xyz, tri.Count > 0 ? tri.ToArray() : null, def: def);

                var newPins = new PinId[anchorList.Count];
                for (int k = 0; k < anchorList.Count; ++k)
                {
                    int v = anchorList[k];
                    if (v < 0 || v >= vertices.Count)
                        throw new ArgumentOutOfRangeException("Anchors", v, "Anchors: vertex " + v + " is not one of the " + vertices.Count + " vertices");
                    newPins[k] = next.CreatePin(b.First + v, new[] { xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2] });
                }

                var rests = new double[goalList.Count];
                var groups = new Dictionary<int, GroupId>();
                int rank = 0;
                foreach (int w in goalList.Select(g => g.Weight).Distinct().OrderBy(w => w))
                    groups[w] = next.CreateGroup(10 + rank++, w);
                for (int i = 0; i < goalList.Count; ++i)
                {
                    var g = goalList[i];
                    var particles = g.Vertices.Select(v => b.First + v).ToArray();
                    next.AddConstraint(g.Kind, particles, g.Rest, g.Compliance, groups[g.Weight]);
                    rests[i] = g.Rest ?? g.Measure(xyz, 0);
                }

                if (world != null) world.Dispose();
                world = next;
                body = b;
                pins = newPins;
                anchors = anchorList.ToArray();
                anchorTargets = anchors.Select(v => vertices[v]).ToArray();
                goals = goalList;
                goalRest = rests;
                faces = faceList;
                gravityNow = gravity;
                massNow = def.Material.Mass;
                double[] built = next.GetBodyMasses(b.Id);
                double total = built.Sum();
                massShares = built.Select(m => m / total).ToArray();
                stretchNow = def.Material.StretchCompliance;
                bendNow = def.Material.BendCompliance;
                dampingNow = solver.Damping;
            }
            catch
            {
                next.Dispose();
                throw;
            }
        }

        /// <summary>Inputs changed since the last solution, applied to the running world without a
        /// reset: gravity (embra_world_set_gravity); the total mass (embra_body_set_masses, each
        /// vertex keeping its share of it, by area as at the build); stretch and bend compliance and
        /// damping (the body's material, embra_body_set_material); the anchors (pins destroyed and
        /// created, each new one holding its vertex where it is now). The mesh, the goals, the
        /// substeps and iterations need a Reset.</summary>
        void ApplyChanges(IGH_DataAccess DA)
        {
            var gravity = Item(DA, InGravity, new Point3d(0, 0, -9.81));
            if (gravity.X != gravityNow.X || gravity.Y != gravityNow.Y || gravity.Z != gravityNow.Z)
            {
                world.SetGravity(gravity.X, gravity.Y, gravity.Z);
                gravityNow = gravity;
            }
            double stretch = Item(DA, InStretchCompliance, 0.0), bend = Item(DA, InBendCompliance, 1.0),
                   damping = Item(DA, InDamping, 0.0);
            if (stretch != stretchNow || bend != bendNow || damping != dampingNow)
            {
                var m = world.GetMaterial(body.Id);
                m.StretchCompliance = stretch;
                m.BendCompliance = bend;
                m.Damping = damping;
                world.SetMaterial(body.Id, m);
                stretchNow = stretch;
                bendNow = bend;
                dampingNow = damping;
            }
            double mass = Item(DA, InMass, 1.0);
            if (mass != massNow)
            {
                // 0 means "density 1 kg/m^2" only when building; a running world needs the total.
                if (!(mass > 0.0) || double.IsInfinity(mass))
                    throw new ArgumentOutOfRangeException("Mass", mass, "Mass: a total mass > 0 kg is needed to change it without a Reset, got " + mass);
                world.SetBodyMasses(body.Id, massShares.Select(share => share * mass).ToArray());
                massNow = mass;
            }
            var anchorList = new List<int>();
            DA.GetDataList(InAnchors, anchorList);
            if (!anchorList.SequenceEqual(anchors))
            {
                foreach (int v in anchorList)
                    if (v < 0 || v >= body.Count)
                        throw new ArgumentOutOfRangeException("Anchors", v, "Anchors: vertex " + v + " is not one of the " + body.Count + " vertices");
                double[] xyz = world.GetPositions(body.First, body.Count);
                foreach (var pin in pins) world.DestroyPin(pin);
                pins = anchorList.Select(v => world.CreatePin(body.First + v, new[] { xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2] })).ToArray();
                anchors = anchorList.ToArray();
                anchorTargets = anchors.Select(v => new Point3d(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2])).ToArray();
            }
        }

        void Output(IGH_DataAccess DA)
        {
            double[] xyz = world.GetPositions(body.First, body.Count);
            var points = new List<Point3d>(body.Count);
            for (int i = 0; i < body.Count; ++i) points.Add(new Point3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]));
            DA.SetDataList(OutVertices, points);
            DA.SetDataList(OutGoalErrors, goals.Select((g, i) => g.Error(xyz, 0, goalRest[i])).ToList());
            DA.SetDataList(OutAnchorErrors, anchors.Select((v, k) => points[v].DistanceTo(anchorTargets[k])).ToList());
            var report = world.Report;
            DA.SetData(OutResidual, report.ResidualMax);
            DA.SetData(OutKineticEnergy, report.KineticEnergy);
            DA.SetData(OutSettled, report.Settled != 0);
            DA.SetData(OutFrame, (int)report.Frame);
            DA.SetData(OutMesh, new ListMesh(points.Cast<IPoint3d>(), faces));
            Message = report.Settled != 0 ? "settled" : "frame " + report.Frame;
        }

        /// <summary>The positions as a flat xyz array (what the Vertices output holds), for hosts that
        /// want the numbers without Point3d.</summary>
        public double[] PositionsXyz() { return world == null ? new double[0] : world.GetPositions(body.First, body.Count); }

        public void Dispose()
        {
            if (world != null) world.Dispose();
            world = null;
        }
    }
}
