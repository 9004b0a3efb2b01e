// The C# bindings against the C host: the Gaudi tent bit for bit, every error path as a .NET
// exception with the C message, worlds on parallel tasks, and the Grasshopper-style component.
// Environment (tests/adapters/CMakeLists.txt): EMBRA_CLI (the `embra` command), EMBRA_SOURCE_DIR.
using System;
using System.Collections.Generic;
using System.Diagnostics;
using System.Globalization;
using System.IO;
using System.Linq;
using System.Reflection;
using System.Runtime.InteropServices;
using System.Text.RegularExpressions;
using System.Threading;
using System.Threading.Tasks;
using Embra;
using Embra.Grasshopper;
using NUnit.Framework;

namespace Embra.Tests
{
    static class Tent
    {
        /// <summary>The mesh of `embra demo tent` (host_adapters/cli/embra_cli.c), same arithmetic, same order.</summary>
        public static void Mesh(int rows, double side, out double[] xyz, out int[] tri, out int[] corners)
        {
            double h = side * Math.Sqrt(3.0) / 2.0;
            int n = (rows + 1) * (rows + 2) / 2;
            xyz = new double[3 * n];
            tri = new int[3 * rows * rows];
            int v = 0, t = 0;
            for (int r = 0; r <= rows; ++r)
                for (int c = 0; c <= rows - r; ++c)
                {
                    xyz[3 * v] = side * ((double)c + 0.5 * r) / rows - side / 2;
                    xyz[3 * v + 1] = h * (double)r / rows - h / 3;
                    xyz[3 * v + 2] = 0.0;
                    ++v;
                }
            Func<int, int, int> idx = (r, c) => r * (rows + 1) - (r * (r - 1)) / 2 + c;
            for (int r = 0; r < rows; ++r)
                for (int c = 0; c < rows - r; ++c)
                {
                    tri[t++] = idx(r, c); tri[t++] = idx(r, c + 1); tri[t++] = idx(r + 1, c);
                    if (c + 1 < rows - r) { tri[t++] = idx(r, c + 1); tri[t++] = idx(r + 1, c + 1); tri[t++] = idx(r + 1, c); }
                }
            corners = new[] { idx(0, 0), idx(0, rows), idx(rows, 0) };
        }

        public static double Draw(int frame) { return frame < 60 ? frame / 60.0 : 1.0; }

        /// <summary>The tent built and stepped through World, as the C host does it.</summary>
        public static double[] Run(int frames, int rows = 40)
        {
            double[] xyz; int[] tri, corners;
            Mesh(rows, 1.0, out xyz, out tri, out corners);
            var solver = Library.DefaultSolverDef();
            unsafe { solver.Gravity[2] = +9.81; }
            solver.Damping = 2.0;
            solver.Substeps = 20;
            solver.Iterations = 4;
            solver.SettleSpeed = 1e-3;
            using (var w = new World(solver))
            {
                var stretch = w.CreateGroup(0, 2);
                var bend = w.CreateGroup(1, 1);
                var def = Native.embra_default_body_def();
                def.StretchGroup = stretch;
                def.BendGroup = bend;
                def.Material.Mass = 0.5;
                def.Material.StretchCompliance = 1e-2;
                def.Material.BendCompliance = 10.0;
                var body = w.CreateBody(xyz, tri, def: def);
                var pins = corners.Select(k => w.CreatePin(body.First + k, new[] { xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2] })).ToArray();
                for (int f = 1; f <= frames; ++f)
                {
                    double draw = Draw(f);
                    for (int k = 0; k < 3; ++k)
                    {
                        var target = new double[3];
                        for (int c = 0; c < 3; ++c) target[c] = xyz[3 * corners[k] + c] * (1.0 - 0.1 * draw);
                        w.SetPinTarget(pins[k], target);
                    }
                    w.Step();
                }
                return w.GetPositions(body.First, body.Count);
            }
        }
    }

    static class Env
    {
        public static string Source { get { return Environment.GetEnvironmentVariable("EMBRA_SOURCE_DIR"); } }

        public static string TempDir()
        {
            string d = Path.Combine(Path.GetTempPath(), "embra-cs-" + Guid.NewGuid().ToString("N"));
            Directory.CreateDirectory(d);
            return d;
        }

        /// <summary>Runs the `embra` command with --out into a new folder, which it returns (the caller deletes it).</summary>
        public static string CliRun(params string[] args)
        {
            string dir = TempDir();
            var start = new ProcessStartInfo(Environment.GetEnvironmentVariable("EMBRA_CLI"),
                string.Join(" ", args.Select(a => "\"" + a + "\"")) + " --out \"" + dir + "\"")
            { UseShellExecute = false, RedirectStandardOutput = true };
            using (var p = Process.Start(start))
            {
                p.StandardOutput.ReadToEnd();
                p.WaitForExit();
                Assert.AreEqual(0, p.ExitCode, "embra " + string.Join(" ", args));
            }
            return dir;
        }

        /// <summary>The 'v' lines of an OBJ written by the `embra` command (%.17g: exact).</summary>
        public static double[] ObjVertices(string path)
        {
            var values = new List<double>();
            foreach (var line in File.ReadAllLines(path))
                if (line.StartsWith("v "))
                    values.AddRange(line.Split(' ').Skip(1).Take(3).Select(s => double.Parse(s, CultureInfo.InvariantCulture)));
            return values.ToArray();
        }

        /// <summary>Runs the `embra` command and returns the 'v' lines of DIR/final.obj.</summary>
        public static double[] Cli(params string[] args)
        {
            string dir = CliRun(args);
            double[] values = ObjVertices(Path.Combine(dir, "final.obj"));
            Directory.Delete(dir, true);
            return values;
        }

        public static void AssertBitIdentical(double[] expected, double[] actual)
        {
            Assert.AreEqual(expected.Length, actual.Length);
            for (int i = 0; i < expected.Length; ++i)
                if (BitConverter.DoubleToInt64Bits(expected[i]) != BitConverter.DoubleToInt64Bits(actual[i]))
                    Assert.Fail("value " + i + " differs: " + expected[i].ToString("R") + " vs " + actual[i].ToString("R"));
        }
    }

    [TestFixture]
    public class TentTests
    {
        [Test]
        public void TentBuiltInCSharpMatchesTheCHostBitForBit()
        {
            double[] c = Env.Cli("demo", "tent", "--frames", "100", "--every", "1000");
            double[] cs = Tent.Run(100);
            Assert.AreEqual(3 * 861, cs.Length);
            Env.AssertBitIdentical(c, cs);
            Assert.Greater(Enumerable.Range(0, 861).Max(i => cs[3 * i + 2]), 0.05);  // it has risen: the comparison means something
        }

        [Test]
        public void HangingNetIsWrittenWithItsLinksAsObjLines()
        {
            // examples/hanging_net.json: edges, no triangles; its OBJ holds the stepped positions exactly
            // and its 220 links as `l` lines, so an edge-only mesh renders (embra_world_export_obj).
            string scene = Path.Combine(Env.Source, "examples", "hanging_net.json");
            using (var w = World.LoadFile(scene))
            {
                w.Step(20);
                string dir = Env.TempDir();
                string file = Path.Combine(dir, "net.obj");
                w.WriteObj(file);
                string text = File.ReadAllText(file);
                Assert.AreEqual(w.ExportObj(), text);
                string[] lines = text.Split('\n');
                double[] v = lines.Where(l => l.StartsWith("v ")).SelectMany(l => l.Split(' ').Skip(1))
                    .Select(t => double.Parse(t, System.Globalization.CultureInfo.InvariantCulture)).ToArray();
                Env.AssertBitIdentical(w.GetPositions(), v);
                Assert.Less(Enumerable.Range(0, v.Length / 3).Min(i => v[3 * i + 2]), -0.01);  // it has sagged
                Assert.AreEqual(0, lines.Count(l => l.StartsWith("f ")));
                var links = lines.Where(l => l.StartsWith("l ")).ToList();
                Assert.AreEqual(220, links.Count);
                int first, count;
                w.GetBodyParticles(w.Bodies()[0], out first, out count);
                // The scene's edges, in its text: [[0, 1], [0, 11], ...].
                string json = File.ReadAllText(scene);
                string edges = json.Substring(json.IndexOf("\"edges\": [") + 10);
                edges = edges.Substring(0, edges.IndexOf("]]") + 2);
                var expected = System.Text.RegularExpressions.Regex.Matches(edges, @"\[(\d+), (\d+)\]").Cast<System.Text.RegularExpressions.Match>()
                    .Select(m => "l " + (first + int.Parse(m.Groups[1].Value) + 1) + " " + (first + int.Parse(m.Groups[2].Value) + 1)).ToList();
                expected.Sort(string.CompareOrdinal);
                links.Sort(string.CompareOrdinal);
                CollectionAssert.AreEqual(expected, links);
                Assert.Throws<EmbraArgumentException>(() => w.WriteObj(Path.Combine(dir, "missing", "net.obj")));
                Directory.Delete(dir, true);
            }
        }

        [Test]
        public void TentSceneLoadedInCSharpMatchesTheCHostBitForBit()
        {
            string scene = Path.Combine(Env.Source, "examples", "gaudi_tent.json");
            double[] c = Env.Cli("run", scene, "--frames", "100");
            using (var w = World.LoadFile(scene))
            {
                Assert.AreEqual(600, w.SceneFrames);
                w.Step(100);
                Assert.AreEqual(100, w.Report.Frame);
                Env.AssertBitIdentical(c, w.GetPositions());
            }
            using (var w = World.LoadJson(File.ReadAllText(scene)))
            {
                w.Step(100);
                Env.AssertBitIdentical(c, w.GetPositions());
            }
        }

        [Test]
        public void TentThroughTheComponentMatchesTheCHostBitForBit()
        {
            double[] c = Env.Cli("demo", "tent", "--frames", "100", "--every", "1000");
            double[] xyz; int[] tri, corners;
            Tent.Mesh(40, 1.0, out xyz, out tri, out corners);
            var vertices = Enumerable.Range(0, xyz.Length / 3).Select(i => new Point3d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2])).ToList();
            var faces = Enumerable.Range(0, tri.Length / 3).Select(i => new MeshFace(tri[3 * i], tri[3 * i + 1], tri[3 * i + 2])).ToList();
            using (var component = new FormFindingComponent())
            {
                var da = new DataAccess()
                    .Set(FormFindingComponent.InVertices, vertices).Set(FormFindingComponent.InFaces, faces)
                    .Set(FormFindingComponent.InAnchors, corners.ToList())
                    .Set(FormFindingComponent.InGravity, new Point3d(0, 0, 9.81)).Set(FormFindingComponent.InMass, 0.5)
                    .Set(FormFindingComponent.InStretchCompliance, 1e-2).Set(FormFindingComponent.InBendCompliance, 10.0)
                    .Set(FormFindingComponent.InStretchWeight, 2).Set(FormFindingComponent.InDamping, 2.0)
                    .Set(FormFindingComponent.InSubsteps, 20).Set(FormFindingComponent.InIterations, 4)
                    .Set(FormFindingComponent.InReset, true).Set(FormFindingComponent.InRun, false);
                component.ComputeData(da);  // Reset: build, no step
                da.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                for (int f = 1; f <= 100; ++f)  // the timer ticks; the author drags the anchors inwards
                {
                    double draw = Tent.Draw(f);
                    da.Set(FormFindingComponent.InAnchorTargets, corners.Select(k => new Point3d(
                        xyz[3 * k] * (1.0 - 0.1 * draw), xyz[3 * k + 1] * (1.0 - 0.1 * draw), xyz[3 * k + 2] * (1.0 - 0.1 * draw))).ToList());
                    component.ComputeData(da);
                    Assert.IsEmpty(component.RuntimeMessages);
                }
                Assert.AreEqual(100, da.Get<int>(FormFindingComponent.OutFrame));
                var points = da.GetList<Point3d>(FormFindingComponent.OutVertices);
                Env.AssertBitIdentical(c, points.SelectMany(p => new[] { p.X, p.Y, p.Z }).ToArray());
                Assert.That(da.GetList<double>(FormFindingComponent.OutAnchorErrors).All(e => e == 0.0));  // hard anchors
            }
        }
    }

    /// <summary>The canvas's timer, driven by hand: the component's requests for another solution are
    /// queued; Tick runs the first one (expiring the component) and says whether there was one.</summary>
    sealed class ManualScheduler : ISolutionScheduler
    {
        readonly Queue<Action> pending = new Queue<Action>();
        public int Requests;
        public readonly List<int> Intervals = new List<int>();

        public void ScheduleSolution(int intervalMs, Action expire)
        {
            ++Requests;
            Intervals.Add(intervalMs);
            pending.Enqueue(expire);
        }

        public bool Tick()
        {
            if (pending.Count == 0) return false;
            pending.Dequeue()();
            return true;
        }
    }

    [TestFixture]
    public class GrasshopperComponentTests
    {
        const int N = 11;                            // vertices along a side: a 1 m square, 0.1 m quads
        static readonly int[] Corners = { 0, N - 1, N * (N - 1), N * N - 1 };
        const int Centre = (N * N) / 2;

        /// <summary>A flat 1 m square of 10 x 10 quads at z = 0, as a Rhino mesh holds it.</summary>
        static ListMesh Square()
        {
            var v = new List<IPoint3d>();
            for (int j = 0; j < N; ++j)
                for (int i = 0; i < N; ++i) v.Add(new Point3d(0.1 * i, 0.1 * j, 0.0));
            var f = new List<MeshFace>();
            for (int j = 0; j + 1 < N; ++j)
                for (int i = 0; i + 1 < N; ++i) f.Add(new MeshFace(j * N + i, j * N + i + 1, (j + 1) * N + i + 1, (j + 1) * N + i));
            return new ListMesh(v, f);
        }

        static DataAccess Inputs(IMeshLike mesh)
        {
            return new DataAccess()
                .Set(FormFindingComponent.InMesh, mesh).Set(FormFindingComponent.InAnchors, Corners.ToList())
                .Set(FormFindingComponent.InMass, 0.5).Set(FormFindingComponent.InStretchCompliance, 1e-3)
                .Set(FormFindingComponent.InBendCompliance, 10.0).Set(FormFindingComponent.InDamping, 4.0)
                .Set(FormFindingComponent.InSubsteps, 20).Set(FormFindingComponent.InIterations, 2)
                .Set(FormFindingComponent.InReset, true).Set(FormFindingComponent.InRun, false);
        }

        /// <summary>Runs the canvas: solves, then solves again on each of the component's requests, at
        /// most `solutions` times in all. Returns the solutions run.</summary>
        static int Run(FormFindingComponent c, DataAccess da, ManualScheduler timer, int solutions)
        {
            bool expired = true;
            c.SolutionExpired = () => expired = true;
            int n = 0;
            while (n < solutions && expired)
            {
                expired = false;
                c.ComputeData(da);
                Assert.IsEmpty(c.RuntimeMessages);
                ++n;
                if (n < solutions) timer.Tick();
            }
            return n;
        }

        static double Z(DataAccess da, int vertex) { return da.Get<IMeshLike>(FormFindingComponent.OutMesh).Vertices[vertex].Z; }

        /// <summary>A mesh in, a mesh out with the same faces on the moved vertices; with Run on the
        /// component asks for its next solution every time, so the square, held at its corners, sags;
        /// with Run off it asks for none and stays at its frame.</summary>
        [Test]
        public void MeshInMeshOutAndKeepsSteppingWhileRunIsOn()
        {
            var square = Square();
            var timer = new ManualScheduler();
            using (var c = new FormFindingComponent { Scheduler = timer })
            {
                var da = Inputs(square);
                c.ComputeData(da);  // Reset: build, no step, no request
                Assert.AreEqual(0, timer.Requests);
                da.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                Assert.AreEqual(150, Run(c, da, timer, 150));  // one solution started by hand, 149 by the timer
                Assert.AreEqual(150, timer.Requests);
                Assert.That(timer.Intervals.All(ms => ms == c.IntervalMs));
                Assert.AreEqual(150, da.Get<int>(FormFindingComponent.OutFrame));

                var mesh = da.Get<IMeshLike>(FormFindingComponent.OutMesh);
                var points = da.GetList<Point3d>(FormFindingComponent.OutVertices);
                Assert.AreEqual(N * N, mesh.Vertices.Count);
                CollectionAssert.AreEqual(square.Faces, mesh.Faces);
                for (int i = 0; i < N * N; ++i)
                {
                    Assert.AreEqual(points[i].X, mesh.Vertices[i].X);
                    Assert.AreEqual(points[i].Z, mesh.Vertices[i].Z);
                }
                foreach (int k in Corners) Assert.AreEqual(0.0, mesh.Vertices[k].Z);  // hard anchors
                Assert.Less(mesh.Vertices[Centre].Z, -0.02);                            // sagged under gravity
                Console.WriteLine("centre after 150 frames: z = {0:E3} m", mesh.Vertices[Centre].Z);

                da.Set(FormFindingComponent.InRun, false);
                Assert.IsTrue(timer.Tick());  // the solution the last running one scheduled
                c.ComputeData(da);
                Assert.AreEqual(150, timer.Requests);  // and no further request
                Assert.IsFalse(timer.Tick());
                Assert.AreEqual(150, da.Get<int>(FormFindingComponent.OutFrame));
            }
        }

        /// <summary>Inputs changed while running act on the running world, no reset (the frame count
        /// goes on): gravity reversed mirrors the sag (the same square under +g is the mirror image of
        /// it under -g); a softer membrane sags deeper; a vertex made an anchor stays where it was; a
        /// changed mass is reported as waiting for a Reset.</summary>
        [Test]
        public void ChangedInputsApplyWithoutAReset()
        {
            var timer = new ManualScheduler();
            using (var c = new FormFindingComponent { Scheduler = timer })
            {
                var da = Inputs(Square());
                c.ComputeData(da);
                da.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                Run(c, da, timer, 300);
                double down = Z(da, Centre);

                da.Set(FormFindingComponent.InGravity, new Point3d(0, 0, 9.81));
                Run(c, da, timer, 300);
                double up = Z(da, Centre);
                Assert.AreEqual(600, da.Get<int>(FormFindingComponent.OutFrame));
                Console.WriteLine("centre: {0:E6} m under -g, {1:E6} m under +g", down, up);
                Assert.Less(down, -0.02);
                Assert.AreEqual(-down, up, 1e-6);  // measured 1.4e-7 m apart

                da.Set(FormFindingComponent.InStretchCompliance, 1e-1);
                Run(c, da, timer, 300);
                double soft = Z(da, Centre);
                Console.WriteLine("centre: {0:E6} m with stretch compliance 1e-1 m/N", soft);
                Assert.Greater(soft, 2.0 * up);  // measured 0.469 m against 0.096 m

                var held = da.Get<IMeshLike>(FormFindingComponent.OutMesh).Vertices[Centre];
                da.Set(FormFindingComponent.InAnchors, Corners.Concat(new[] { Centre }).ToList());
                da.Set(FormFindingComponent.InGravity, new Point3d(0, 0, -9.81));
                Run(c, da, timer, 120);
                var now = da.Get<IMeshLike>(FormFindingComponent.OutMesh).Vertices[Centre];
                Assert.AreEqual(held.X, now.X);
                Assert.AreEqual(held.Y, now.Y);
                Assert.AreEqual(held.Z, now.Z);
                Assert.AreEqual(5, da.GetList<double>(FormFindingComponent.OutAnchorErrors).Count);
                Assert.AreEqual(1020, da.Get<int>(FormFindingComponent.OutFrame));

                da.Set(FormFindingComponent.InMass, -1.0).Set(FormFindingComponent.InRun, false);
                c.ComputeData(da);
                Assert.AreEqual(1, c.RuntimeMessages.Count);
                Assert.AreEqual(GH_RuntimeMessageLevel.Error, c.RuntimeMessages[0].Key);
                StringAssert.Contains("Mass", c.RuntimeMessages[0].Value);
            }
        }

        /// <summary>A changed total mass acts on the running world (no reset: the frame count goes on),
        /// each vertex keeping its share of it: the square made twice as heavy while running sags deeper
        /// and comes to rest where a square built with that mass does (the rest state depends on the
        /// masses, not on the path).</summary>
        [Test]
        public void AChangedMassActsWithoutAReset()
        {
            var timer = new ManualScheduler();
            using (var c = new FormFindingComponent { Scheduler = timer })
            using (var twice = new FormFindingComponent())
            {
                var da = Inputs(Square());
                c.ComputeData(da);
                da.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                Run(c, da, timer, 400);
                double light = Z(da, Centre);

                da.Set(FormFindingComponent.InMass, 1.0);  // built with 0.5 kg
                Run(c, da, timer, 900);
                Assert.AreEqual(1300, da.Get<int>(FormFindingComponent.OutFrame));
                var heavy = da.Get<IMeshLike>(FormFindingComponent.OutMesh).Vertices;

                var reference = Inputs(Square()).Set(FormFindingComponent.InMass, 1.0);
                var referenceTimer = new ManualScheduler();
                twice.Scheduler = referenceTimer;
                twice.ComputeData(reference);
                reference.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                Run(twice, reference, referenceTimer, 1300);
                var expected = reference.Get<IMeshLike>(FormFindingComponent.OutMesh).Vertices;
                double worst = 0.0;
                for (int i = 0; i < N * N; ++i)
                    worst = Math.Max(worst, Math.Abs(heavy[i].Z - expected[i].Z) + Math.Abs(heavy[i].X - expected[i].X) + Math.Abs(heavy[i].Y - expected[i].Y));
                Console.WriteLine("centre: {0:E6} m at 0.5 kg, {1:E6} m at 1 kg (no reset), {2:E6} m built at 1 kg; worst vertex {3:E2} m apart",
                                  light, heavy[Centre].Z, expected[Centre].Z, worst);
                Assert.Less(heavy[Centre].Z, light - 1e-3);
                Assert.Less(worst, 1e-6);
            }
        }
    }

    [TestFixture]
    public class ConstraintKindTests
    {
        /// <summary>Four links between fixed ends, neighbours held equal (sharing a particle): a quarter each.</summary>
        [Test]
        public void EqualLengthSplitsAPinnedLineEvenly()
        {
            var solver = Library.DefaultSolverDef();
            unsafe { solver.Gravity[2] = 0.0; }
            solver.Substeps = 4;
            solver.Iterations = 4;
            solver.Damping = 20.0;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0, 0, 0, 0.1, 0, 0, 0.5, 0, 0, 0.6, 0, 0, 1, 0, 0 },
                             masses: new[] { 0.0, 1.0, 2.0, 0.5, 0.0 }, def: def);
                Assert.AreEqual(3, w.AddConstraints(ConstraintKind.EqualLength, new[] { 0, 1, 1, 2, 1, 2, 2, 3, 2, 3, 3, 4 },
                                                    new double[] { 0, 0, 0 }));
                w.Step(200);
                var p = w.GetPositions();
                for (int i = 0; i < 4; ++i)
                {
                    double dx = p[3 * i + 3] - p[3 * i], dy = p[3 * i + 4] - p[3 * i + 1], dz = p[3 * i + 5] - p[3 * i + 2];
                    Assert.AreEqual(0.25, Math.Sqrt(dx * dx + dy * dy + dz * dz), 1e-9, "link " + i);
                }
            }
        }

        /// <summary>A hexagon with its corners up and down in turn, held planar: every corner ends on the
        /// plane through corners 0, 2 and 4, and a corner given twice is refused.</summary>
        [Test]
        public void PolygonPlanarityFlattensASkewHexagon()
        {
            var solver = Library.DefaultSolverDef();
            unsafe { solver.Gravity[2] = 0.0; }
            solver.Substeps = 4;
            solver.Iterations = 10;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                var xyz = new double[18];
                for (int k = 0; k < 6; ++k)
                {
                    xyz[3 * k] = Math.Cos(k * Math.PI / 3);
                    xyz[3 * k + 1] = Math.Sin(k * Math.PI / 3);
                    xyz[3 * k + 2] = k % 2 == 0 ? 0.2 : -0.2;
                }
                w.CreateBody(xyz, masses: new[] { 1.0, 1.0, 1.0, 1.0, 1.0, 1.0 }, def: def);
                Assert.AreEqual(6, w.AddPolygonPlanarity(new[] { 0, 1, 2, 3, 4, 5 }));
                w.Step(200);
                var p = w.GetPositions();
                Func<int, int, double> at = (k, i) => p[3 * k + i] - p[i];  // corner k from corner 0
                double nx = at(2, 1) * at(4, 2) - at(2, 2) * at(4, 1), ny = at(2, 2) * at(4, 0) - at(2, 0) * at(4, 2),
                       nz = at(2, 0) * at(4, 1) - at(2, 1) * at(4, 0);
                double len = Math.Sqrt(nx * nx + ny * ny + nz * nz);
                for (int k = 0; k < 6; ++k)
                    Assert.AreEqual(0.0, (at(k, 0) * nx + at(k, 1) * ny + at(k, 2) * nz) / len, 1e-9, "corner " + k);
                Assert.Throws<EmbraArgumentException>(() => w.AddPolygonPlanarity(new[] { 0, 1, 2, 1 }));
            }
        }

        /// <summary>Six points under one hard shape match, one pinned, swing under gravity with every
        /// pairwise distance kept to 1e-6 m; removed; a point given twice is refused.</summary>
        [Test]
        public void ShapeMatchKeepsItsShape()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 4;
            solver.Iterations = 40;
            solver.Tethers = 0;
            var xyz = new double[] { 0, 0, 1, 0.4, 0, 1, 0, 0.4, 1, 0, 0, 1.4, 0.3, 0.3, 1.3, -0.2, 0.1, 1.2 };
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(xyz, masses: new[] { 1.0, 2.0, 1.0, 1.0, 0.5, 1.0 }, def: def);
                Assert.AreEqual(0, w.AddShapeMatch(new[] { 0, 1, 2, 3, 4, 5 }));
                w.CreatePin(0, new[] { 0.0, 0.0, 1.0 });
                w.Step(60);
                var p = w.GetPositions();
                Func<double[], int, int, double> d = (x, i, j) =>
                    Math.Sqrt(Math.Pow(x[3 * i] - x[3 * j], 2) + Math.Pow(x[3 * i + 1] - x[3 * j + 1], 2) +
                              Math.Pow(x[3 * i + 2] - x[3 * j + 2], 2));
                for (int i = 0; i < 6; ++i)
                    for (int j = i + 1; j < 6; ++j) Assert.AreEqual(d(xyz, i, j), d(p, i, j), 1e-6, i + "-" + j);
                Assert.AreEqual(1, w.ShapeMatchCount());
                w.RemoveShapeMatch(0);
                Assert.AreEqual(0, w.ShapeMatchCount());
                Assert.Throws<EmbraArgumentException>(() => w.AddShapeMatch(new[] { 0, 1, 1 }));
            }
        }

        /// <summary>Six points braced rigid (4 n - 9 = 15 constraints), one pinned, fall and turn under
        /// gravity with every pairwise distance kept to 1e-6 m; a point given twice is refused.</summary>
        [Test]
        public void RigidSetKeepsItsShape()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 4;
            solver.Iterations = 40;
            solver.Tethers = 0;
            var xyz = new double[] { 0, 0, 1, 0.4, 0, 1, 0, 0.4, 1, 0, 0, 1.4, 0.3, 0.3, 1.3, -0.2, 0.1, 1.2 };
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(xyz, masses: new[] { 1.0, 1.0, 1.0, 1.0, 1.0, 1.0 }, def: def);
                Assert.AreEqual(15, w.AddRigidSet(new[] { 0, 1, 2, 3, 4, 5 }));
                w.CreatePin(0, new[] { 0.0, 0.0, 1.0 });
                w.Step(60);
                var p = w.GetPositions();
                Func<double[], int, int, double> d = (x, i, j) =>
                    Math.Sqrt(Math.Pow(x[3 * i] - x[3 * j], 2) + Math.Pow(x[3 * i + 1] - x[3 * j + 1], 2) +
                              Math.Pow(x[3 * i + 2] - x[3 * j + 2], 2));
                for (int i = 0; i < 6; ++i)
                    for (int j = i + 1; j < 6; ++j) Assert.AreEqual(d(xyz, i, j), d(p, i, j), 1e-6, i + "-" + j);
                Assert.Throws<EmbraArgumentException>(() => w.AddRigidSet(new[] { 0, 1, 1 }));
            }
        }
    }

    public class SolveTests
    {
        // A 1 m pendulum let go 0.1 rad from the vertical, no damping: still moving, oscillating with
        // the small-angle period 2 pi sqrt(L / g) (1 + 0.1^2 / 16), to 1 %.
        [Test]
        public void APendulumOscillatesWithItsPeriod()
        {
            using (var w = new World())
            {
                double theta = 0.1;
                var b = w.CreateBody(new[] { 0.0, 0.0, 0.0, Math.Sin(theta), 0.0, -Math.Cos(theta) }, masses: new[] { 0.0, 1.0 });
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 });
                var r = w.Solve(SolveUntil.Tolerance, 900);
                double expected = 2 * Math.PI * Math.Sqrt(1 / 9.81) * (1 + theta * theta / 16);
                Assert.AreEqual((int)Solve.Oscillating, r.Outcome);
                Assert.AreEqual(900, r.Frames);
                Assert.AreEqual(expected, r.Period, 0.01 * expected);
                Assert.AreEqual(-1, r.WorstMetric);
            }
        }

        // One panel, its top corners pinned, one of them 5 cm off the plane of the others: at rest, out
        // of tolerance, and the worst metric is that panel's top layer.
        [Test]
        public void APanelPinnedOffItsPlaneSettlesOutOfTolerance()
        {
            var solver = Library.FormFindingSolverDef();
            solver.Damping = 2.0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultPanelMeshDef();
                def.GridColumns = 1;
                def.GridRows = 1;
                def.Pins = (int)PanelPins.TopCorners;
                var body = w.CreatePanelMesh(def);
                foreach (var pin in w.Pins())
                {
                    if (w.PinParticle(pin) != body.First + 2) continue;
                    var t = w.PinTarget(pin);
                    w.SetPinTarget(pin, new[] { t[0], t[1], t[2] + 0.05 });
                }
                var r = w.Solve();
                Assert.AreEqual((int)Solve.SettledOutOfTolerance, r.Outcome);
                Assert.Less(r.Frames, 1000);
                Assert.IsTrue(r.WorstMetric == (int)PanelMetric.Planarity || r.WorstMetric == (int)PanelMetric.CornerDistance);
                Assert.AreEqual(body.Id.Index, r.WorstBody.Index);
                Assert.AreEqual(0, r.WorstElement);
                Assert.AreEqual(0, r.WorstLayer);
                Assert.Greater(r.WorstValue, 100 * r.WorstTarget);
            }
        }

        // A hard rod's residual is | |x1 - x0| - L | from the positions, in metres.
        [Test]
        public void ResidualsByKindInTheirUnits()
        {
            using (var w = new World())
            {
                var b = w.CreateBody(new[] { 0.0, 0.0, 0.0, 0.6, 0.0, -0.8 }, masses: new[] { 0.0, 1.0 });
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 });
                Assert.AreEqual(0, w.Residuals().Length);
                w.Step(10);
                var res = w.Residuals();
                Assert.AreEqual(1, res.Length);
                Assert.AreEqual((int)ConstraintKind.Distance, res[0].Kind);
                Assert.AreEqual("m", Library.ResidualUnit(res[0].Kind));
                Assert.AreEqual("distance", Library.ResidualName(res[0].Kind));
                Assert.AreEqual("rad", Library.ResidualUnit((int)ConstraintKind.Dihedral));
                Assert.AreEqual("pins", Library.ResidualName((int)Residual.Pins));
                Assert.IsNull(Library.ResidualUnit(99));
                var x = w.GetPositions();
                double length = Math.Sqrt(Math.Pow(x[3] - x[0], 2) + Math.Pow(x[4] - x[1], 2) + Math.Pow(x[5] - x[2], 2));
                Assert.AreEqual(1, res[0].Count);
                Assert.AreEqual(Math.Abs(length - 1.0), res[0].Max, 1e-15);
            }
        }

        // A hanging cable's top held by two soft pins (1e-3 m/N) 0.5 m to either side, each in its own
        // group: 500 N each way on one particle; that pair is named first.
        [Test]
        public void TwoGroupsPullingACableApartAreNamedFirst()
        {
            var solver = Library.DefaultSolverDef();
            solver.Damping = 5.0;
            using (var w = new World(solver))
            {
                var xyz = new double[33];
                for (int i = 0; i < 11; ++i) xyz[3 * i + 2] = -0.1 * i;
                var def = Library.DefaultBodyDef();
                def.Material.Mass = 1.0;
                var b = w.CreateBody(xyz, def: def);
                for (int i = 0; i < 10; ++i) w.AddConstraint(ConstraintKind.Distance, new[] { b.First + i, b.First + i + 1 });
                var left = w.CreateGroup(order: 1);
                var right = w.CreateGroup(order: 2);
                var pa = w.CreatePin(b.First, new[] { -0.5, 0, 0 }, 1e-3, left);
                var pb = w.CreatePin(b.First, new[] { 0.5, 0, 0 }, 1e-3, right);
                w.Step(300);
                var first = w.GroupConflicts()[0];
                Assert.AreEqual(left.Index, first.A.Index);
                Assert.AreEqual(right.Index, first.B.Index);
                Assert.AreEqual(500.0, first.Force, 10.0);
                Assert.AreEqual(1, first.Particles);
                var worst = w.WorstConstraints(3);
                Assert.AreEqual(3, worst.Length);
                Assert.AreEqual((int)Residual.Pins, worst[0].Kind);
                Assert.IsTrue((worst[0].Pin.Index == pa.Index && worst[1].Pin.Index == pb.Index) ||
                              (worst[0].Pin.Index == pb.Index && worst[1].Pin.Index == pa.Index));
                Assert.AreEqual(0.5, worst[0].Violation, 0.02);
                Assert.AreEqual(500.0, worst[0].Force, 10.0);
                Assert.AreEqual((int)ConstraintKind.Distance, worst[2].Kind);
                var links = w.GroupResiduals(w.DefaultGroup, ConstraintKind.Distance);
                Assert.AreEqual(10, links.Length);
                Assert.Less(links.Max(), 2e-4);
            }
        }

        [Test]
        public void ABadBudgetIsRefusedAndNothingSteps()
        {
            using (var w = new World())
            {
                w.CreateBody(new[] { 0.0, 0.0, 0.0 });
                var d = Library.DefaultSolveDef();
                d.MaxFrames = 0;
                Assert.Throws<EmbraArgumentException>(() => w.Solve(d));
                Assert.AreEqual(0, w.Report.Frame);
            }
        }
    }

    [TestFixture]
    public class StaticsTests
    {
        /// <summary>A load hung from two pins by two hard bars at 45 degrees: each bar carries the load
        /// over 2 sin 45 (N, tension), and the reactions sum to minus every weight and point load.</summary>
        [Test]
        public void TwoBarTrussForcesAndReactions()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 4;
            solver.Iterations = 20;
            solver.Damping = 5.0;
            solver.Tethers = 0;
            solver.RealignPasses = 2;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { -1, 0, 0, 1, 0, 0, 0, 0, -1 }, masses: new[] { 1.0, 1.5, 2.0 }, def: def);
                w.AddConstraints(ConstraintKind.Distance, new[] { 0, 2, 1, 2 });
                var p0 = w.CreatePin(0, new double[] { -1, 0, 0 });
                var p1 = w.CreatePin(1, new double[] { 1, 0, 0 });
                w.SetLoads(new double[] { 0, 0, -10 }, 2);
                Assert.AreEqual(new double[] { 0, 0, 0, 0, 0, 0, 0, 0, -10 }, w.GetLoads());
                w.Step(200);
                double down = 2 * 9.81 + 10;
                foreach (double t in w.ConstraintForces(w.DefaultGroup, ConstraintKind.Distance))
                    Assert.AreEqual(down / Math.Sqrt(2.0), t, 1e-9 * down);
                var r = w.Reactions();
                Assert.AreEqual(2, r.Length);
                Assert.AreEqual(p0, r[0].Pin);
                Assert.AreEqual(p1, r[1].Pin);
                double[] total = new double[3];
                unsafe
                {
                    for (int i = 0; i < 2; ++i)
                    {
                        Reaction ri = r[i];
                        for (int k = 0; k < 3; ++k) total[k] += ri.Force[k];
                    }
                }
                Assert.AreEqual(0.0, total[0], 1e-9 * down);
                Assert.AreEqual(0.0, total[1], 1e-9 * down);
                Assert.AreEqual(4.5 * 9.81 + 10, total[2], 1e-9 * down);
                Assert.Throws<EmbraArgumentException>(() => w.ConstraintForces(w.DefaultGroup, ConstraintKind.Weld));
                Assert.Throws<EmbraArgumentException>(() => w.SetLoads(new double[] { 0, double.NaN, 0 }, 0));
                Assert.AreEqual(new double[] { 0, 0, 0 }, w.GetLoads(0, 1));
            }
        }

        /// <summary>Three loose particles (1, 1.5, 2 kg) resting on the ground plane z = 0, one with a point
        /// load whose horizontal part friction holds: the plane's force is minus every weight and load,
        /// its moment about its origin minus the loads' moment (N, N m, to 1e-9 relative).</summary>
        [Test]
        public void GroundPlaneReactionCarriesTheWeightsAndLoads()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 4;
            solver.Iterations = 20;
            solver.Damping = 5.0;
            solver.Tethers = 0;
            solver.RealignPasses = 2;
            using (var w = new World(solver))
            {
                var floorDef = Library.DefaultColliderDef();
                floorDef.Shape = (int)ColliderShape.Plane;
                var floor = w.CreateCollider(floorDef);
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                double[] masses = { 1.0, 1.5, 2.0 };
                w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0, 0, 1, 0 }, masses: masses, def: def);
                w.SetLoads(new double[] { 0.5, 0, -2 }, 2);
                w.Step(50);
                var loads = new double[3, 3];
                for (int i = 0; i < 3; ++i) loads[i, 2] = -9.81 * masses[i];
                loads[2, 0] = 0.5;
                loads[2, 2] -= 2.0;
                double[] p = w.GetPositions();
                double[] total = new double[3], moment = new double[3];
                for (int i = 0; i < 3; ++i)
                {
                    for (int k = 0; k < 3; ++k) total[k] += loads[i, k];
                    moment[0] += p[3 * i + 1] * loads[i, 2] - p[3 * i + 2] * loads[i, 1];
                    moment[1] += p[3 * i + 2] * loads[i, 0] - p[3 * i] * loads[i, 2];
                    moment[2] += p[3 * i] * loads[i, 1] - p[3 * i + 1] * loads[i, 0];
                }
                var r = w.ColliderReactions();
                Assert.AreEqual(1, r.Length);
                Assert.AreEqual(floor, r[0].Collider);
                Assert.AreEqual(3, r[0].Contacts);
                double scale = Math.Sqrt(total[0] * total[0] + total[1] * total[1] + total[2] * total[2]);
                double mscale = Math.Sqrt(moment[0] * moment[0] + moment[1] * moment[1] + moment[2] * moment[2]);
                unsafe
                {
                    ColliderReaction c = r[0];
                    for (int k = 0; k < 3; ++k)
                    {
                        Assert.AreEqual(-total[k], c.Force[k], 1e-9 * scale);
                        Assert.AreEqual(-moment[k], c.Moment[k], 1e-9 * mscale);
                    }
                }
                Assert.AreEqual(0, w.Reactions().Length);
            }
        }

        /// <summary>A free triangle of three 0.5 kg particles (0.5 m^2) under 12 Pa per true area along
        /// (0, 3, -4): 2 N, 4 m/s^2 on each corner; a free edge of length 2 under (1, 0, 0) N/m: 1 N on
        /// each end (symplectic Euler: a h^2 n (n + 1) / 2 after n substeps). Refusals change nothing.</summary>
        [Test]
        public void AreaAndLineLoadsPushFreeParticles()
        {
            var solver = Library.DefaultSolverDef();
            unsafe { solver.Gravity[2] = 0.0; }
            solver.Substeps = 4;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                var start = new double[] { 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 5, 2, 0, 5 };
                w.CreateBody(start, masses: new[] { 0.5, 0.5, 0.5, 0.5, 0.5 }, def: def);
                w.SetAreaLoads(new[] { World.MakeAreaLoad(0, 1, 2, 12.0, AreaLoadMode.TrueArea, new double[] { 0, 3, -4 }) });
                w.SetLineLoads(new[] { World.MakeLineLoad(3, 4, new double[] { 1, 0, 0 }) });
                var got = w.AreaLoads();
                Assert.AreEqual(1, got.Length);
                Assert.AreEqual((int)AreaLoadMode.TrueArea, got[0].Mode);
                Assert.AreEqual(12.0, got[0].Pressure);
                Assert.AreEqual(1, w.LineLoads().Length);
                w.Step(3);
                int n = 12;
                double h = 1.0 / 60.0 / 4;
                double s = h * h * n * (n + 1) / 2;
                var p = w.GetPositions();
                var u = new[] { 0.0, 0.6, -0.8 };
                for (int i = 0; i < 3; ++i)
                    for (int k = 0; k < 3; ++k) Assert.AreEqual(start[3 * i + k] + 4 * u[k] * s, p[3 * i + k], 1e-12);
                for (int i = 3; i < 5; ++i) Assert.AreEqual(start[3 * i] + 2 * s, p[3 * i], 1e-12);
                Assert.Throws<EmbraArgumentException>(() => w.SetAreaLoads(new[] { World.MakeAreaLoad(0, 1, 1, 1.0) }));
                Assert.Throws<EmbraArgumentException>(() => w.SetLineLoads(new[] { World.MakeLineLoad(3, 5, new double[] { 1, 0, 0 }) }));
                Assert.AreEqual(12.0, w.AreaLoads()[0].Pressure);
                w.SetAreaLoads(new AreaLoad[0]);
                w.SetLineLoads(new LineLoad[0]);
                Assert.AreEqual(0, w.AreaLoads().Length + w.LineLoads().Length);
            }
        }

        /// <summary>A bead on a vertical circle-shaped polyline (48 segments, radius 0.6) swings under
        /// gravity and stays on it to 1e-9 m at every frame (distance to every segment computed here).</summary>
        [Test]
        public void PolylineSupportHoldsABeadOnACircle()
        {
            int n = 48;
            var pts = new double[3 * n];
            for (int k = 0; k < n; ++k)
            {
                double a = -Math.PI / 2 + Math.PI / n + 2 * Math.PI * k / n;
                pts[3 * k] = 0.6 * Math.Cos(a);
                pts[3 * k + 2] = 0.6 * Math.Sin(a);
            }
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 8;
            solver.Iterations = 2;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0.6, 0, 0.1 }, masses: new[] { 0.3 }, def: def);
                var pin = w.CreatePolylineSupport(0, pts, closed: true);
                double low = double.PositiveInfinity;
                for (int f = 0; f < 60; ++f)
                {
                    w.Step();
                    var q = w.GetPositions();
                    double best = double.PositiveInfinity;
                    for (int s = 0; s < n; ++s)
                    {
                        int b = (s + 1) % n;
                        double ex = pts[3 * b] - pts[3 * s], ez = pts[3 * b + 2] - pts[3 * s + 2];
                        double t = ((q[0] - pts[3 * s]) * ex + (q[2] - pts[3 * s + 2]) * ez) / (ex * ex + ez * ez);
                        t = Math.Min(1.0, Math.Max(0.0, t));
                        double dx = q[0] - pts[3 * s] - t * ex, dz = q[2] - pts[3 * s + 2] - t * ez;
                        best = Math.Min(best, Math.Sqrt(dx * dx + q[1] * q[1] + dz * dz));
                    }
                    Assert.Less(best, 1e-9);
                    low = Math.Min(low, q[2]);
                }
                Assert.Less(low, -0.5);
                Assert.AreEqual(pin, w.Reactions()[0].Pin);
                Assert.Throws<EmbraArgumentException>(() => w.CreatePolylineSupport(0, new double[] { 0, 0, 0, 0, 0, 0 }));
            }
        }

        /// <summary>A particle on a mesh support (two triangles of a square inclined at 30 degrees) slides
        /// down it on the discrete path of g sin(theta) and the reaction is m g cos(theta) along the normal;
        /// a degenerate triangle is refused.</summary>
        [Test]
        public void MeshSupportHoldsAParticleSlidingDownAnInclinedFace()
        {
            double th = Math.PI / 6;
            var n = new[] { -Math.Sin(th), 0.0, Math.Cos(th) };
            var down = new[] { -Math.Cos(th), 0.0, -Math.Sin(th) };
            var ab = new[] { 1, 1, -1, 1, -1, -1, 1, -1 };
            var verts = new double[12];
            for (int v = 0; v < 4; ++v)
                for (int k = 0; k < 3; ++k) verts[3 * v + k] = 10 * (ab[2 * v] * down[k] + (k == 1 ? ab[2 * v + 1] : 0));
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 10;
            solver.Iterations = 1;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0, 0.3, 0 }, masses: new[] { 2.0 }, def: def);
                var pin = w.CreateMeshSupport(0, verts, new[] { 0, 3, 2, 0, 2, 1 });
                w.Step(30);
                int steps = 300;
                double h = 1.0 / 60.0 / 10;
                var p = w.GetPositions();
                double along = p[0] * down[0] + p[2] * down[2];
                double exact = 9.81 * Math.Sin(th) * h * h * steps * (steps + 1) / 2;
                // rounding of the closest point (vertices of size 10) carried on by the velocity: steps^2 eps 10
                Assert.AreEqual(exact, along, steps * steps * 2.2e-16 * 10);
                Assert.AreEqual(0.0, p[0] * n[0] + p[2] * n[2], 1e-12);
                Reaction r0 = w.Reactions()[0];
                Assert.AreEqual(pin, r0.Pin);
                unsafe
                {
                    for (int k = 0; k < 3; ++k) Assert.AreEqual(2 * 9.81 * Math.Cos(th) * n[k], r0.Force[k], 1e-9 * 9.81);
                }
                Assert.Throws<EmbraArgumentException>(
                    () => w.CreateMeshSupport(0, new double[] { 0, 0, 0, 1, 0, 0, 2, 0, 0 }, new[] { 0, 1, 2 }));
            }
        }

        /// <summary>PolylineSupportPoints reads the points exactly as created; SetPinTarget moves the
        /// target (and so the curve) and leaves them as they are.</summary>
        [Test]
        public void PolylineSupportPointsReadBackAndMoveWithTheTarget()
        {
            var pts = new double[] { 0, 0, 0, 1.0 / 3.0, 0.1, -0.2, 0.7, -0.4, 0.05 };
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 4;
            solver.Iterations = 2;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0 }, masses: new[] { 1.0, 1.0 }, def: def);
                var pin = w.CreatePolylineSupport(0, pts);
                var plane = w.CreateSupport(1, new double[] { 0, 0, 0 }, PinSupport.Plane, null, 1.0);
                CollectionAssert.AreEqual(pts, w.PolylineSupportPoints(pin));
                w.SetPinTarget(pin, new double[] { 0.25, -1.5, 2.0 });
                w.Step();
                CollectionAssert.AreEqual(pts, w.PolylineSupportPoints(pin));
                CollectionAssert.AreEqual(new double[] { 0.25, -1.5, 2.0 }, w.PinTarget(pin));
                Assert.Throws<EmbraArgumentException>(() => w.PolylineSupportPoints(plane));
            }
        }

        /// <summary>A roller (an axes support holding z) under gravity and a horizontal point load: z stays at
        /// the target's, x and y follow (F / m) h^2 n (n + 1) / 2, and the reaction holds the weight in z
        /// with x and y exactly 0; an axis that is not 0/1 flags is refused.</summary>
        [Test]
        public void AxesSupportHoldsZAndLetsXAndYAccelerate()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 10;
            solver.Iterations = 1;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0.3, -0.4, 1.2 }, masses: new[] { 2.0 }, def: def);
                var pin = w.CreateSupport(0, new double[] { 0.3, -0.4, 1.2 }, PinSupport.Axes, new double[] { 0, 0, 1 });
                w.SetLoads(new double[] { 1.5, 0.5, 0.0 });
                for (int f = 0; f < 30; ++f)
                {
                    w.Step();
                    Assert.AreEqual(1.2, w.GetPositions()[2], 1e-12);
                }
                int steps = 300;
                double h = 1.0 / 60.0 / 10;
                var p = w.GetPositions();
                Assert.AreEqual(0.75 * h * h * steps * (steps + 1) / 2, p[0] - 0.3, 1e-12);
                Assert.AreEqual(0.25 * h * h * steps * (steps + 1) / 2, p[1] + 0.4, 1e-12);
                Reaction r0 = w.Reactions()[0];
                Assert.AreEqual(pin, r0.Pin);
                unsafe
                {
                    Assert.AreEqual(0.0, r0.Force[0]);
                    Assert.AreEqual(0.0, r0.Force[1]);
                    Assert.AreEqual(2 * 9.81, r0.Force[2], 1e-9 * 9.81);
                }
                Assert.Throws<EmbraArgumentException>(
                    () => w.CreateSupport(0, new double[] { 0, 0, 0 }, PinSupport.Axes, new double[] { 0, 0.5, 1 }));
                Assert.Throws<EmbraArgumentException>(
                    () => w.CreateSupport(0, new double[] { 0, 0, 0 }, PinSupport.Axes, new double[] { 0, 0, 0 }));
            }
        }

        /// <summary>A particle on a frictionless plane inclined at 30 degrees slides down it at g sin(theta)
        /// (the exact discrete path) and the support pushes with m g cos(theta) along its normal.</summary>
        [Test]
        public void PlaneSupportSlidesAtGSinTheta()
        {
            double th = Math.PI / 6;
            var n = new[] { -Math.Sin(th), 0.0, Math.Cos(th) };
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 10;
            solver.Iterations = 1;
            solver.Tethers = 0;
            using (var w = new World(solver))
            {
                var def = Library.DefaultBodyDef();
                def.Generate = 0;
                w.CreateBody(new double[] { 0, 0, 0 }, masses: new[] { 2.0 }, def: def);
                var pin = w.CreateSupport(0, new double[] { 0, 0, 0 }, PinSupport.Plane, new[] { 2 * n[0], 2 * n[1], 2 * n[2] });
                w.Step(30);
                int steps = 300;
                double h = 1.0 / 60.0 / 10;
                var p = w.GetPositions();
                double along = -(p[0] * Math.Cos(th) + p[2] * Math.Sin(th));
                double exact = 9.81 * Math.Sin(th) * h * h * steps * (steps + 1) / 2;
                Assert.AreEqual(exact, along, 1e-12 * exact);
                var r = w.Reactions();
                Assert.AreEqual(pin, r[0].Pin);
                Reaction r0 = r[0];
                unsafe
                {
                    for (int k = 0; k < 3; ++k) Assert.AreEqual(2 * 9.81 * Math.Cos(th) * n[k], r0.Force[k], 1e-9 * 9.81);
                }
                Assert.Throws<EmbraArgumentException>(
                    () => w.CreateSupport(0, new double[] { 0, 0, 0 }, PinSupport.Line, new double[] { 0, 0, 0 }));
            }
        }
    }

    public class ErrorTests
    {
        static World Square()
        {
            var w = new World();
            w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 }, new[] { 0, 1, 2, 0, 2, 3 });
            w.Step(3);
            return w;
        }

        static string Snapshot(World w)
        {
            var bits = w.GetPositions().Concat(w.GetVelocities()).Select(v => BitConverter.DoubleToInt64Bits(v).ToString("x"));
            var c = w.Counts;
            return string.Join(",", bits) + "|" + c.Particles + "," + c.Pins + "," + c.Constraints + "|" + w.SaveJson();
        }

        [Test]
        public void OutOfRangeIndex()
        {
            using (var w = Square())
            {
                string before = Snapshot(w);
                var e = Assert.Throws<EmbraArgumentException>(() => w.CreatePin(4, new double[] { 0, 0, 0 }));
                Assert.That(e, Is.InstanceOf<ArgumentException>());
                Assert.AreEqual(Status.InvalidArgument, e.Status);
                Assert.AreEqual("EMBRA_ERROR_INVALID_ARGUMENT", e.StatusName);
                StringAssert.StartsWith("embra_pin_create: ", e.Message);
                Assert.AreEqual(Errors.LastMessage(), e.Message);  // the C message, verbatim
                Assert.Throws<EmbraArgumentException>(() => w.GetPositions(2, 5));
                var bulk = Assert.Throws<EmbraArgumentException>(() => w.AddConstraints(ConstraintKind.Distance, new[] { 0, 1, 2, 99 }));
                StringAssert.StartsWith("embra_constraints_add: ", bulk.Message);
                Assert.Throws<EmbraArgumentException>(() => w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0, 0, 1, 0 }, new[] { 0, 1, 7 }));
                var small = Assert.Throws<EmbraArgumentException>(() => w.GetPositions(0, 4, new double[6]));
                Assert.AreEqual(Status.BufferTooSmall, small.Status);
                Assert.AreEqual(before, Snapshot(w));
            }
        }

        [Test]
        public void NaN()
        {
            using (var w = Square())
            {
                string before = Snapshot(w);
                var e = Assert.Throws<EmbraArgumentException>(() => w.SetGravity(0, double.NaN, 0));
                StringAssert.StartsWith("embra_world_set_gravity: ", e.Message);
                StringAssert.Contains("finite", e.Message);
                Assert.Throws<EmbraArgumentException>(() => w.SetPositions(new[] { double.NaN, 0, 0 }, 1));
                Assert.Throws<EmbraArgumentException>(() => w.CreatePin(0, new[] { 0, 0, double.PositiveInfinity }));
                Assert.AreEqual(before, Snapshot(w));
            }
        }

        [Test]
        public void AStepThatGoesNonFinite()
        {
            using (var w = Square())
            {
                // 1e300 m/s, the largest value a world accepts, overflows in the step (the stretch
                // constraints square lengths of 1e297 m)
                w.SetVelocities(new[] { Limits.MaxAbsValue, 0, 0 }, 1);
                string before = Snapshot(w);
                long frame = w.Report.Frame;
                var e = Assert.Throws<EmbraNumericalException>(() => w.Step());
                Assert.That(e, Is.InstanceOf<ArithmeticException>());
                StringAssert.StartsWith("embra_world_step: non-finite", e.Message);
                Assert.AreEqual(before, Snapshot(w));  // restored to the start of the frame
                Assert.AreEqual(frame, w.Warning.Frame);
                Assert.GreaterOrEqual(w.Warning.Particle, 0);
                w.SetVelocities(new double[] { 0, 0, 0 }, 1);  // the cause removed, the world steps on
                w.Step();
                Assert.AreEqual(frame + 1, w.Report.Frame);
            }
        }

        [Test]
        public void ValuesBeyondTheRangesAreRefusedAndChangeNothing()
        {
            // |v| > 1e300, masses and positives below 1e-300, dt > 1e6, substeps x iterations > 1e5, unit_scale > 1e12
            const double big = 1e308, tiny = Limits.MinPositive / 10;
            using (var w = Square())
            {
                var pin = w.CreatePin(0, new double[] { 0, 0, 0 });
                Func<string> state = () => Snapshot(w) + "|" + string.Join(",", w.PinTarget(pin)) + "|" + w.Solver.Dt +
                    "," + w.Solver.Substeps + "," + w.Solver.Iterations + "|" + w.Tolerances.UnitScale;
                string before = state();
                var refused = new List<Tuple<string, TestDelegate>> {
                    Tuple.Create<string, TestDelegate>("embra_world_set_velocities", () => w.SetVelocities(new[] { big, 0, 0 }, 1)),
                    Tuple.Create<string, TestDelegate>("embra_world_set_positions", () => w.SetPositions(new[] { 0, -2 * Limits.MaxAbsValue, 0 }, 2)),
                    Tuple.Create<string, TestDelegate>("embra_world_set_gravity", () => w.SetGravity(0, 0, big)),
                    Tuple.Create<string, TestDelegate>("embra_pin_set_target", () => w.SetPinTarget(pin, new[] { big, 0, 0 })),
                    Tuple.Create<string, TestDelegate>("embra_pin_create", () => w.CreatePin(1, new[] { 0, big, 0 })),
                    Tuple.Create<string, TestDelegate>("embra_body_create", () => w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0, 0, 1, 0 },
                        new[] { 0, 1, 2 }, masses: new[] { 1, 1, tiny })),
                    Tuple.Create<string, TestDelegate>("embra_world_set_solver", () => { var d = w.Solver; d.Dt = 2 * Limits.MaxDt; w.Solver = d; }),
                    Tuple.Create<string, TestDelegate>("embra_world_set_solver", () => { var d = w.Solver; d.Dt = tiny; w.Solver = d; }),
                    Tuple.Create<string, TestDelegate>("embra_world_set_solver", () => {
                        var d = w.Solver; d.Substeps = 1000; d.Iterations = Limits.MaxPassesPerStep / 1000 + 1; w.Solver = d; }),
                    Tuple.Create<string, TestDelegate>("embra_world_set_tolerances", () => {
                        var t = w.Tolerances; t.UnitScale = 10 * Limits.MaxUnitScale; w.Tolerances = t; }),
                };
                foreach (var r in refused)
                {
                    var e = Assert.Throws<EmbraArgumentException>(r.Item2, r.Item1);
                    StringAssert.StartsWith(r.Item1 + ": ", e.Message);
                }
                Assert.AreEqual(before, state());
            }
        }

        [Test]
        public void ValuesAtTheLimitsAreAcceptedAndTheSavedSceneLoadsBack()
        {
            const double top = Limits.MaxAbsValue;
            var solver = Library.DefaultSolverDef();
            solver.Dt = Limits.MaxDt;
            solver.Substeps = 1000;
            solver.Iterations = Limits.MaxPassesPerStep / 1000;
            unsafe { solver.Gravity[0] = top; solver.Gravity[1] = -top; solver.Gravity[2] = 0; }
            using (var w = new World(solver))
            {
                w.CreateBody(new[] { top, 0, -top }, masses: new[] { Limits.MinPositive });  // one particle each:
                w.CreateBody(new[] { 0, top, 0 }, masses: new[] { top });                   // no element measure
                w.CreatePin(0, new[] { -top, top, top });
                var t = w.Tolerances;
                t.UnitScale = Limits.MaxUnitScale;
                w.Tolerances = t;
                string text = w.SaveJson();
                using (var back = World.LoadJson(text))
                {
                    Assert.AreEqual(text, back.SaveJson());
                    Env.AssertBitIdentical(w.GetPositions(), back.GetPositions());
                }
            }
        }

        [Test]
        public void EveryStatusMapsToItsException()
        {
            var statuses = typeof(Status).GetFields(BindingFlags.Public | BindingFlags.Static)
                .Where(f => f.Name != "Ok").ToDictionary(f => f.Name, f => (int)f.GetValue(null));
            Assert.That(statuses.Keys, Has.Member("Locked").And.Member("Cancelled"));
            Assert.IsInstanceOf<EmbraLockedException>(Errors.For(Status.Locked));
            Assert.IsInstanceOf<InvalidOperationException>(Errors.For(Status.Locked));
            Assert.IsInstanceOf<EmbraCancelledException>(Errors.For(Status.Cancelled));
            Assert.IsInstanceOf<OperationCanceledException>(Errors.For(Status.Cancelled));
            Assert.IsInstanceOf<EmbraNumericalException>(Errors.For(Status.Numerical));
            Assert.AreEqual("EMBRA_ERROR_CANCELLED", Errors.StatusName(Status.Cancelled));
            foreach (var s in statuses)
            {
                var e = Errors.For(s.Value);
                Assert.AreEqual(s.Value, ((IEmbraException)e).Status, s.Key);
                Assert.AreEqual("EMBRA_ERROR_" + Regex.Replace(s.Key, "(?<=.)([A-Z])", "_$1").ToUpperInvariant(),
                                ((IEmbraException)e).StatusName, s.Key);
            }
            // LOCKED, CANCELLED, NUMERICAL and SCHEMA each have a type of their own (the others share
            // ArgumentException / InvalidOperationException types, told apart by Status)
            foreach (int own in new[] { Status.Locked, Status.Cancelled, Status.Numerical, Status.Schema })
                Assert.AreEqual(1, statuses.Values.Count(v => Errors.For(v).GetType() == Errors.For(own).GetType()),
                                Errors.StatusName(own));
        }

        [Test]
        public void UseAfterDestroy()
        {
            using (var w = Square())
            {
                var pin = w.CreatePin(0, new double[] { 0, 0, 0 });
                w.DestroyPin(pin);
                string before = Snapshot(w);
                var e = Assert.Throws<EmbraInvalidOperationException>(() => w.SetPinTarget(pin, new double[] { 1, 0, 0 }));
                Assert.AreEqual(Status.StaleId, e.Status);
                StringAssert.StartsWith("embra_pin_set_target: ", e.Message);
                var g = w.CreateGroup();
                w.DestroyGroup(g);
                Assert.Throws<EmbraInvalidOperationException>(() => w.SetGroupWeight(g, 2));
                Assert.AreEqual(before.Split('|')[0], Snapshot(w).Split('|')[0]);
            }
            var disposed = new World();
            disposed.Dispose();
            disposed.Dispose();  // idempotent
            Assert.IsTrue(disposed.IsDisposed);
            var d = Assert.Throws<EmbraObjectDisposedException>(() => disposed.Step());
            Assert.That(d, Is.InstanceOf<ObjectDisposedException>());
            StringAssert.Contains("embra_world_step: world is NULL", d.Message);
            Assert.Throws<EmbraObjectDisposedException>(() => disposed.GetPositions());
        }

        [Test]
        public void BadScenesAndVersions()
        {
            var e = Assert.Throws<EmbraSchemaException>(() => World.LoadJson("{\"format\": \"embra-scene\", \"version\": 1, \"solver\": {\"dt\": 0}}"));
            StringAssert.Contains("/solver/dt", e.Message);
            Assert.That(e, Is.InstanceOf<FormatException>());
            Assert.Throws<EmbraArgumentException>(() => World.LoadFile("/nonexistent-embra-dir/scene.json"));
            var v = Assert.Throws<EmbraInvalidOperationException>(() => Library.CheckAbi(Native.AbiVersion + 1));
            Assert.AreEqual(Status.Version, v.Status);
            var solver = Library.DefaultSolverDef();
            solver.Version = 7;
            Assert.Throws<EmbraInvalidOperationException>(() => new World(solver));
        }
    }

    /// <summary>examples/poq_drape.json built through World: the paper's 4 x 4 Planar Offset Quad drape
    /// (panels of 0.8, thickness 0.01, the top corners pinned on posts drawn in by 10% over frames 0-30,
    /// a sphere of radius 1 below moved between frames 120 and 180), with the scene player's arithmetic.</summary>
    static class Drape
    {
        public const int Frames = 150;
        public static string Scene { get { return Path.Combine(Env.Source, "examples", "poq_drape.json"); } }

        static readonly double[][] Posts = { new[] { -1.6, -1.6, 0.0 }, new[] { 1.6, -1.6, 0.0 }, new[] { -1.6, 1.6, 0.0 }, new[] { 1.6, 1.6, 0.0 } };
        static readonly double[][] Drawn = { new[] { -1.44, -1.6, 0.0 }, new[] { 1.44, -1.6, 0.0 }, new[] { -1.44, 1.6, 0.0 }, new[] { 1.44, 1.6, 0.0 } };
        static readonly double[] BallFrom = { 0.3, 0.2, -1.45 }, BallTo = { -0.3, 0.2, -1.35 };

        /// <summary>A scene action's value: linear between keys at frames f0 and f1, held outside them.</summary>
        static double[] Keyed(int frame, int f0, double[] a, int f1, double[] b)
        {
            if (frame <= f0) return (double[])a.Clone();
            if (frame > f1) return (double[])b.Clone();
            double t = (double)(frame - f0) / (double)(f1 - f0);
            return Enumerable.Range(0, a.Length).Select(k => (1.0 - t) * a[k] + t * b[k]).ToArray();
        }

        public static World Build(out Body body, out ColliderId ball)
        {
            var solver = Library.DefaultSolverDef();
            solver.Dt = 0.016666666666666666;
            solver.Substeps = 60;
            solver.Iterations = 2;
            solver.SettleSpeed = 0.001;
            var w = new World(solver);
            var def = Library.DefaultPanelMeshDef();
            def.GridColumns = 4;
            def.GridRows = 4;
            def.PanelSize = 0.8;
            unsafe
            {
                def.Origin[0] = -1.6;
                def.Origin[1] = -1.6;
            }
            def.Thickness = 0.01;
            def.Mass = 16;
            def.Damping = 9;
            def.SlideCompliance = 0.001;
            def.Pins = (int)PanelPins.TopCorners;
            body = w.CreatePanelMesh(def);
            var sphere = Library.DefaultColliderDef();
            sphere.Shape = (int)ColliderShape.Sphere;
            unsafe { for (int k = 0; k < 3; ++k) sphere.Position[k] = BallFrom[k]; }
            sphere.Radius = 1.0;
            ball = w.CreateCollider(sphere);
            var t = w.Tolerances;
            t.UnitScale = 1250;
            w.Tolerances = t;
            return w;
        }

        /// <summary>The corner pins CreatePanelMesh made: the world's first four, ids {k, 1}, in the order
        /// the scene names them poq.pin0..3.</summary>
        public static PinId Pin(int k) { return new PinId { Index = (uint)k, Generation = 1 }; }

        public static void Step(World w, ColliderId ball, int frames)
        {
            for (int i = 0; i < frames; ++i)
            {
                int frame = (int)w.Report.Frame + 1;
                for (int k = 0; k < 4; ++k) w.SetPinTarget(Pin(k), Keyed(frame, 0, Posts[k], 30, Drawn[k]));
                w.SetColliderTransform(ball, Keyed(frame, 120, BallFrom, 180, BallTo), new[] { 1.0, 0, 0, 0 });
                w.Step();
            }
        }

        public static void CheckPins(World w)
        {
            for (int k = 0; k < 4; ++k) CollectionAssert.AreEqual(Posts[k], w.PinTarget(Pin(k)));
        }
    }

    [TestFixture]
    public class PanelTests
    {
        [Test]
        public void DrapeBuiltInCSharpMatchesTheCHostBitForBit()
        {
            string dir = Env.CliRun("run", Drape.Scene, "--frames", Drape.Frames.ToString());
            try
            {
                Body body;
                ColliderId ball;
                using (var w = Drape.Build(out body, out ball))
                {
                    Assert.AreEqual(128, body.Count);
                    Assert.AreEqual(16, w.PanelCount(body.Id));
                    Drape.CheckPins(w);
                    Drape.Step(w, ball, Drape.Frames);
                    double[] cs = w.GetPositions(body.First, body.Count);
                    Env.AssertBitIdentical(Env.ObjVertices(Path.Combine(dir, "final.obj")), cs);
                    Assert.Less(Enumerable.Range(0, 128).Min(i => cs[3 * i + 2]), -0.5);  // folded over the sphere
                    Assert.AreEqual(File.ReadAllText(Path.Combine(dir, "panels_0.json")), w.ExportCuts(body.Id));
                    Assert.AreEqual(File.ReadAllText(Path.Combine(dir, "panels_0.csv")), w.ExportCuts(body.Id, CutsFormat.Csv));
                    string last = File.ReadAllLines(Path.Combine(dir, "metrics.jsonl")).Last();
                    var m = w.PanelMetrics(body.Id);
                    StringAssert.Contains("\"frame\":" + Drape.Frames + ",", last);
                    Assert.AreEqual(Field(last, "thickness_error_max"), m.Thickness.Max);
                    Assert.AreEqual(Field(last, "miter_error_max"), m.Miter.Max);
                    Assert.AreEqual(Field(last, "planarity_top_max"), m.PlanarityTop.Max);
                    Assert.AreEqual(Field(last, "planarity_bottom_max"), m.PlanarityBottom.Max);
                    Assert.AreEqual(Field(last, "conical_defect_max"), m.Conical.Max);
                    Assert.AreEqual(Field(last, "corner_gap_max"), w.CornerGap(body.Id).Max);
                    StringAssert.Contains("\"within_tolerance\":" + (m.WithinTolerance == 1 ? "true" : "false"), last);
                }
            }
            finally
            {
                Directory.Delete(dir, true);
            }
        }

        static double Field(string record, string name)
        {
            var m = Regex.Match(record, "\"" + name + "\":([^,}]+)");
            Assert.IsTrue(m.Success, name);
            return double.Parse(m.Groups[1].Value, CultureInfo.InvariantCulture);
        }

        [Test]
        public void DrapeSceneLoadedInCSharpStepsAsTheOneBuilt()
        {
            Body body;
            ColliderId ball;
            using (var built = Drape.Build(out body, out ball))
            using (var loaded = World.LoadFile(Drape.Scene))
            {
                Assert.AreEqual(built.Tolerances, loaded.Tolerances);
                Assert.AreEqual(1250.0, loaded.Tolerances.UnitScale);
                Drape.Step(built, ball, 100);
                loaded.Step(100);
                Env.AssertBitIdentical(loaded.GetPositions(), built.GetPositions());
                var m = loaded.PanelMetrics(body.Id);
                Assert.AreEqual(m, built.PanelMetrics(body.Id));
                Assert.AreEqual(PanelMetrics.CurrentVersion, m.Version);
                Assert.LessOrEqual(m.Thickness.Max, 5e-5);  // the paper's bars at frame 100
                Assert.LessOrEqual(m.PlanarityTop.Max, 1e-6);
                Assert.LessOrEqual(m.PlanarityBottom.Max, 1e-6);
                Assert.LessOrEqual(m.Miter.Max, 1e-3);
                Assert.AreEqual(16, m.Thickness.Count);
                Assert.AreEqual(40, m.Miter.Count);
                Assert.AreEqual(9, m.Conical.Count);

                double[] miter = loaded.VertexErrors(body.Id, PanelMetric.Miter);
                Assert.AreEqual(128, miter.Length);
                Assert.AreEqual(m.Miter.Max, miter.Max());
                Assert.Greater(miter.Max(), 0.0);
                Assert.AreEqual(Math.Max(m.PlanarityTop.Max, m.PlanarityBottom.Max), loaded.VertexErrors(body.Id, PanelMetric.Planarity).Max());
                Assert.AreEqual(m.Thickness.Max, loaded.VertexErrors(body.Id, PanelMetric.Thickness).Max());
                var into = Enumerable.Repeat(7.0, 130).ToArray();
                Assert.AreSame(into, loaded.VertexErrors(body.Id, PanelMetric.Miter, into));
                Env.AssertBitIdentical(miter, into.Take(128).ToArray());
                CollectionAssert.AreEqual(new[] { 7.0, 7.0 }, into.Skip(128));
            }
        }

        [Test]
        public void ALoadedSceneNamesItsObjectsThroughTheIdLists()
        {
            using (var w = World.LoadFile(Drape.Scene))
            {
                // The scene's pins, in its order: the four top corners of the 4 x 4 panel mesh.
                CollectionAssert.AreEqual(new[] { 0, 25, 99, 122 }, w.Pins().Select(p => w.PinParticle(p)).ToArray());
                Assert.AreEqual(1, w.Bodies().Length);
                CollectionAssert.AreEqual(new[] { w.DefaultGroup, w.ContactGroup }, w.Groups());
                var ball = w.Colliders().Single();
                double[] at, rot;
                w.ColliderTransform(ball, out at, out rot);
                CollectionAssert.AreEqual(new[] { 0.3, 0.2, -1.45 }, at);
                CollectionAssert.AreEqual(new[] { 1.0, 0.0, 0.0, 0.0 }, rot);
                w.Step(150);  // halfway along the sphere's path from frame 120 to 180
                w.ColliderTransform(ball, out at, out rot);
                Assert.AreEqual(0.0, at[0], 1e-12);
                Assert.AreEqual(0.2, at[1], 1e-12);
                Assert.AreEqual(-1.4, at[2], 1e-12);
                var stale = Assert.Throws<EmbraInvalidOperationException>(() => w.PinParticle(new PinId { Index = 0, Generation = 9 }));
                Assert.AreEqual(Status.StaleId, stale.Status);
            }
        }

        [Test]
        public void GridPinsTolerancesAndAMeshOfQuads()
        {
            using (var w = new World())
            {
                var def = Library.DefaultPanelMeshDef();
                Assert.AreEqual(PanelMeshDef.CurrentVersion, def.Version);
                Assert.AreEqual(0.8, def.PanelSize);
                Assert.AreEqual(1e-3, def.SlideCompliance);
                Assert.AreEqual(0.3, def.FrictionDynamic);
                def.GridColumns = 2;
                def.GridRows = 3;
                def.Pins = (int)PanelPins.TopAndBottomCorners;
                var body = w.CreatePanelMesh(def);
                Assert.AreEqual(0, body.First);
                Assert.AreEqual(48, body.Count);
                Assert.AreEqual(48, w.Counts.Particles);
                Assert.AreEqual(8, w.Counts.Pins);
                var m = w.PanelMetrics(body.Id);
                Assert.AreEqual(1, m.WithinTolerance);
                Assert.AreEqual(2 * 4 + 3 * 3, m.Miter.Count);

                var t = Library.DefaultTolerances();
                Assert.AreEqual(Tolerances.CurrentVersion, t.Version);
                Assert.AreEqual(1000.0, t.UnitScale);
                Assert.AreEqual(5e-5, t.Thickness.Target);
                Assert.AreEqual(1e-2, t.Miter.Max);
                Assert.AreEqual(t, w.Tolerances);
                var custom = t;
                custom.Miter.Target = 0.5;
                custom.Miter.Max = 1.0;
                w.Tolerances = custom;
                Assert.AreEqual(custom, w.Tolerances);

                // One corner 2 cm off its panel's plane: out of the world's tolerances, within looser ones.
                var p = w.GetPositions(0, 1);
                p[2] += 0.02;
                w.SetPositions(p, 0);
                var strict = w.PanelMetrics(body.Id);
                Assert.AreEqual(0, strict.WithinTolerance);
                Assert.GreaterOrEqual(strict.PlanarityTop.AboveMax, 1);
                var loose = t;
                loose.Planarity = loose.PlanarityDistance = loose.Thickness = loose.Miter = new Tolerance { Target = 1.0, Max = 1.0 };
                var within = w.PanelMetrics(body.Id, loose);
                Assert.AreEqual(1, within.WithinTolerance);
                Assert.AreEqual(6, within.PlanarityTop.WithinTarget);
                Assert.AreEqual(strict.PlanarityTop.Max, within.PlanarityTop.Max);

                var xyz = new double[] { 0, 0, 1, 1, 0, 1, 2, 0, 1, 0, 1, 1, 1, 1, 1, 2, 1, 1 };
                var quads = new[] { 0, 1, 4, 3, 1, 2, 5, 4 };
                var thick = Library.DefaultPanelMeshDef();
                thick.Thickness = 0.05;
                var two = w.CreatePanelMesh(thick, xyz, quads);
                Assert.AreEqual(48, two.First);
                Assert.AreEqual(16, two.Count);
                Assert.AreEqual(2, w.PanelCount(two.Id));
                Assert.AreEqual(7, w.PanelMetrics(two.Id).Miter.Count);
                double[] z = w.GetPositions(two.First, 8).Where((v, i) => i % 3 == 2).ToArray();
                CollectionAssert.AreEqual(new[] { 1.0, 1.0, 1.0, 1.0 }, z.Take(4));
                Assert.That(z.Skip(4).All(v => Math.Abs(v - 0.95) < 1e-12));  // the bottom layer 0.05 below
                Assert.AreEqual(3, w.ExportCuts(two.Id, CutsFormat.Csv).Split(new[] { '\n' }, StringSplitOptions.RemoveEmptyEntries).Length);
            }
        }

        static string Snapshot(World w)
        {
            var bits = w.GetPositions().Concat(w.GetVelocities()).Select(v => BitConverter.DoubleToInt64Bits(v).ToString("x"));
            var c = w.Counts;
            var t = w.Tolerances;
            return string.Join(",", bits) + "|" + c.Particles + "," + c.Bodies + "," + c.Pins + "," + c.Constraints + "|" +
                   t.UnitScale.ToString("R") + "," + t.Miter.Target.ToString("R") + "|" + w.SaveJson();
        }

        [Test]
        public void RefusedPanelCallsThrowTheCMessageAndChangeNothing()
        {
            using (var w = new World())
            {
                var body = w.CreatePanelMesh();
                var plain = w.CreateBody(new double[] { 0, 0, 0, 1, 0, 0, 0, 1, 0 }, new[] { 0, 1, 2 });
                w.Step(5);
                string before = Snapshot(w);

                var def = Library.DefaultPanelMeshDef();
                def.Version = 99;
                var v = Assert.Throws<EmbraInvalidOperationException>(() => w.CreatePanelMesh(def));
                Assert.AreEqual(Status.Version, v.Status);
                StringAssert.StartsWith("embra_panel_mesh_create: ", v.Message);
                Assert.AreEqual(Errors.LastMessage(), v.Message);
                def = Library.DefaultPanelMeshDef();
                def.PanelSize = double.NaN;
                var nan = Assert.Throws<EmbraArgumentException>(() => w.CreatePanelMesh(def));
                Assert.That(nan, Is.InstanceOf<ArgumentException>());
                StringAssert.StartsWith("embra_panel_mesh_create: panel size must be finite", nan.Message);
                Assert.AreEqual(Errors.LastMessage(), nan.Message);  // the C message, verbatim
                Assert.Throws<EmbraArgumentException>(() => w.CreatePanelMesh(null, new double[] { 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0 }, new[] { 0, 1, 2, 9 }));
                Assert.Throws<ArgumentException>(() => w.CreatePanelMesh(null, new double[] { 0, 0, 0 }, null));  // refused before C

                var missing = new BodyId { Index = 7, Generation = 1 };
                var stale = Assert.Throws<EmbraInvalidOperationException>(() => w.PanelMetrics(missing));
                Assert.AreEqual(Status.StaleId, stale.Status);
                StringAssert.StartsWith("embra_panel_mesh_get_metrics: ", stale.Message);
                Assert.Throws<EmbraInvalidOperationException>(() => w.PanelCount(missing));
                Assert.Throws<EmbraInvalidOperationException>(() => w.VertexErrors(missing, PanelMetric.Miter));
                Assert.Throws<EmbraInvalidOperationException>(() => w.ExportCuts(missing));
                var notPanels = Assert.Throws<EmbraArgumentException>(() => w.ExportCuts(plain.Id));
                StringAssert.Contains("not a panel mesh", notPanels.Message);
                Assert.Throws<EmbraArgumentException>(() => w.VertexErrors(body.Id, (PanelMetric)9));
                Assert.Throws<EmbraArgumentException>(() => w.ExportCuts(body.Id, (CutsFormat)7));

                var into = Enumerable.Repeat(7.0, 127).ToArray();  // 16 panels: 128 values needed
                var small = Assert.Throws<EmbraArgumentException>(() => w.VertexErrors(body.Id, PanelMetric.Thickness, into));
                Assert.AreEqual(Status.BufferTooSmall, small.Status);
                StringAssert.StartsWith("embra_panel_mesh_get_vertex_errors: buffer holds 127", small.Message);
                Assert.That(into.All(x => x == 7.0));

                var t = Library.DefaultTolerances();
                t.Miter.Target = 2.0;  // above its max
                var bad = Assert.Throws<EmbraArgumentException>(() => w.Tolerances = t);
                StringAssert.StartsWith("embra_world_set_tolerances: ", bad.Message);
                t = Library.DefaultTolerances();
                t.UnitScale = double.NaN;
                Assert.Throws<EmbraArgumentException>(() => w.PanelMetrics(body.Id, t));
                Assert.AreEqual(before, Snapshot(w));
            }
        }
    }

    [TestFixture]
    public class ThreadTests
    {
        static double[] Cloth(int seed)
        {
            const int grid = 8;
            var xyz = new double[3 * grid * grid];
            for (int i = 0; i < grid; ++i)
                for (int j = 0; j < grid; ++j)
                {
                    xyz[3 * (i * grid + j)] = 0.1 * j;
                    xyz[3 * (i * grid + j) + 1] = 0.1 * i;
                    xyz[3 * (i * grid + j) + 2] = 0.05 * seed;
                }
            var tri = new List<int>();
            for (int i = 0; i + 1 < grid; ++i)
                for (int j = 0; j + 1 < grid; ++j)
                {
                    int v = i * grid + j;
                    tri.AddRange(new[] { v, v + 1, v + grid + 1, v, v + grid + 1, v + grid });
                }
            var solver = Library.DefaultSolverDef();
            solver.Iterations = 2;
            using (var w = new World(solver))
            {
                var def = Native.embra_default_body_def();
                def.Material.Mass = 0.1 * (seed + 1);
                var body = w.CreateBody(xyz, tri.ToArray(), def: def);
                w.CreatePin(body.First, new[] { xyz[0], xyz[1], xyz[2] });
                w.CreatePin(body.First + grid - 1, new[] { xyz[3 * grid - 3], xyz[3 * grid - 2], xyz[3 * grid - 1] });
                for (int f = 0; f < 60; ++f)
                {
                    w.Step();
                    var e = Assert.Throws<EmbraArgumentException>(() => w.CreatePin(10000 + seed, new double[] { 0, 0, 0 }));
                    StringAssert.Contains((10000 + seed).ToString(), e.Message);  // this task's message, not the other's
                }
                return w.GetPositions();
            }
        }

        [Test]
        public void TwoWorldsOnTwoTasksEqualOneAfterTheOther()
        {
            var alone = new[] { Cloth(0), Cloth(1) };
            var tasks = new[] { Task.Run(() => Cloth(0)), Task.Run(() => Cloth(1)) };
            Task.WaitAll(tasks);
            Env.AssertBitIdentical(alone[0], tasks[0].Result);
            Env.AssertBitIdentical(alone[1], tasks[1].Result);
            Assert.IsFalse(alone[0].SequenceEqual(alone[1]));  // different scenes: equality is no coincidence
        }

        static World Chain()
        {
            var w = new World();
            var def = Native.embra_default_body_def();
            def.Material.Mass = 0.5;
            w.CreateBody(Enumerable.Range(0, 8).SelectMany(i => new[] { 0.1 * i, 0, 0 }).ToArray(),
                         edges: Enumerable.Range(0, 7).SelectMany(i => new[] { i, i + 1 }).ToArray(), def: def);
            w.CreatePin(0, new double[] { 0, 0, 0 });
            return w;
        }

        [Test]
        public void TasksSharingOneWorldTakeTurns()
        {
            double[] expected;
            using (var alone = Chain())
            {
                alone.Step(60);
                expected = alone.GetPositions();
            }
            using (var shared = Chain())
            {
                Task.WaitAll(Task.Run(() => shared.Step(30)), Task.Run(() => shared.Step(30)));
                Assert.AreEqual(60, shared.Report.Frame);
                Env.AssertBitIdentical(expected, shared.GetPositions());
            }
            // Disposed while a task steps: the task's loop ends with ObjectDisposedException, no crash.
            var w = Chain();
            var stepping = Task.Run(() => { while (true) w.Step(); });
            while (w.Report.Frame < 5) { }
            w.Dispose();
            var e = Assert.Throws<AggregateException>(() => stepping.Wait());
            Assert.That(e.InnerException, Is.InstanceOf<ObjectDisposedException>());
            StringAssert.Contains("world is NULL", e.InnerException.Message);
        }

        /// <summary>A pinned n x n cloth stepped with the most passes a step may take (substeps x iterations
        /// = EMBRA_MAX_PASSES_PER_STEP): one frame takes seconds.</summary>
        static World LongCloth(int n)
        {
            var xyz = new List<double>();
            var tri = new List<int>();
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j)
                    xyz.AddRange(new[] { 0.05 * j, 0.05 * i, 0 });
            for (int i = 0; i + 1 < n; ++i)
                for (int j = 0; j + 1 < n; ++j)
                {
                    int v = i * n + j;
                    tri.AddRange(new[] { v, v + 1, v + n + 1, v, v + n + 1, v + n });
                }
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 1000;
            solver.Iterations = Limits.MaxPassesPerStep / 1000;
            var w = new World(solver);
            var def = Native.embra_default_body_def();
            def.Material.Mass = 0.1;
            w.CreateBody(xyz.ToArray(), tri.ToArray(), def: def);
            w.CreatePin(0, new[] { xyz[0], xyz[1], xyz[2] });
            w.CreatePin(n - 1, new[] { xyz[3 * n - 3], xyz[3 * n - 2], xyz[3 * n - 1] });
            return w;
        }

        /// <summary>A call on the world made around the World's turns (Native, World.Handle) is refused with LOCKED.</summary>
        static bool HeldByAnotherCall(World w)
        {
            WorldCounts c;
            return Native.embra_world_get_counts(w.Handle.DangerousGetHandle(), out c) == Status.Locked;
        }

        [Test]
        public void CancelFromAnotherThreadStopsALongStep()
        {
            using (var w = LongCloth(24))
            {
                string before = w.SaveJson();
                long frame = w.Report.Frame;
                Exception outcome = null;
                bool completed = false;
                var stepper = new Thread(() =>
                {
                    while (true)
                    {
                        try { w.Step(); completed = true; return; }
                        catch (EmbraLockedException) { }  // HeldByAnotherCall's probe had the world just then
                        catch (Exception failure) { outcome = failure; return; }
                    }
                });
                stepper.Start();
                while (!HeldByAnotherCall(w))  // the step is in progress
                    Assert.IsTrue(stepper.IsAlive, "the step ended before it was seen in progress");
                w.Cancel();  // takes no turn: the step holds it
                stepper.Join();
                Assert.IsFalse(completed, "the step was not cancelled");
                Assert.IsInstanceOf<EmbraCancelledException>(outcome);
                Assert.IsInstanceOf<OperationCanceledException>(outcome);
                var e = (EmbraCancelledException)outcome;
                Assert.AreEqual(Status.Cancelled, e.Status);
                Assert.AreEqual("EMBRA_ERROR_CANCELLED", e.StatusName);
                StringAssert.StartsWith("embra_world_step: ", e.Message);
                Assert.AreEqual(before, w.SaveJson());  // as before the frame
                Assert.AreEqual(frame, w.Report.Frame);
                var solver = w.Solver;  // the request was consumed: the world steps on
                solver.Substeps = 2;
                solver.Iterations = 1;
                w.Solver = solver;
                w.Step();
                Assert.AreEqual(frame + 1, w.Report.Frame);
            }
            using (var w = LongCloth(4))
            {
                string before = w.SaveJson();
                w.Cancel();  // no step in progress: the next one stops before its first iteration
                Assert.Throws<EmbraCancelledException>(() => w.Step());
                Assert.AreEqual(before, w.SaveJson());
            }
            var disposed = new World();
            disposed.Dispose();
            var d = Assert.Throws<EmbraObjectDisposedException>(() => disposed.Cancel());
            StringAssert.Contains("embra_world_cancel: world is NULL", d.Message);
        }

        [Test]
        public void RawCallsAroundTheWorldsTurnsGetLockedNeverACrash()
        {
            // Native calls on one world from two threads with no turns between them: while one steps, the
            // other's calls are refused with LOCKED and change nothing; every status is OK or LOCKED, and the
            // frame count is the number of steps that returned OK.
            using (var w = Chain())
            {
                IntPtr ptr = w.Handle.DangerousGetHandle();
                var stepStatuses = new List<int>();
                var otherStatuses = new List<int>();
                var lockedErrors = new List<Exception>();
                double lastGravity = -9.81;
                var done = new ManualResetEventSlim();
                var stepper = new Thread(() =>
                {
                    for (int i = 0; i < 200000; ++i)
                    {
                        lock (lockedErrors) if (lockedErrors.Count >= 20) break;
                        stepStatuses.Add(Native.embra_world_step(ptr));
                    }
                    done.Set();
                });
                var other = new Thread(() =>
                {
                    var xyz = new double[24];
                    for (int i = 1; !done.IsSet; ++i)
                    {
                        var g = new double[] { 0, 0, -(i % 50) };
                        int status = Native.embra_world_set_gravity(ptr, g);
                        otherStatuses.Add(status);
                        if (status == Status.Ok) lastGravity = g[2];
                        int read = Native.embra_world_get_positions(ptr, xyz, xyz.Length, 0, 8);
                        otherStatuses.Add(read);
                        foreach (int s in new[] { status, read })
                            if (s == Status.Locked)
                                lock (lockedErrors) lockedErrors.Add(Errors.For(s));  // this thread's C message
                    }
                });
                stepper.Start();
                other.Start();
                stepper.Join();
                other.Join();
                CollectionAssert.IsSubsetOf(stepStatuses.Concat(otherStatuses).Distinct().ToList(), new[] { Status.Ok, Status.Locked });
                Assert.GreaterOrEqual(lockedErrors.Count, 20, "calls overlapping a step");
                foreach (var e in lockedErrors)
                {
                    Assert.IsInstanceOf<EmbraLockedException>(e);
                    StringAssert.Contains("in use by a call in progress", e.Message);
                }
                Assert.AreEqual((long)stepStatuses.Count(s => s == Status.Ok), w.Report.Frame);
                var solver = w.Solver;
                unsafe { Assert.AreEqual(lastGravity, solver.Gravity[2]); }  // refused calls changed nothing
                w.Step();
            }
        }

        [Test]
        public void TwoTentsOnTwoTasksEqualOneAfterTheOther()
        {
            double[] alone = Tent.Run(20);
            var tasks = new[] { Task.Run(() => Tent.Run(20)), Task.Run(() => Tent.Run(20)) };
            Task.WaitAll(tasks);
            Env.AssertBitIdentical(alone, tasks[0].Result);
            Env.AssertBitIdentical(alone, tasks[1].Result);
        }
    }

    [TestFixture]
    public class ApiTests
    {
        [Test]
        public void EveryExternIsExported()
        {
            // Each generated DllImport binds: Marshal.Prelink loads the symbol (a library older than the
            // bindings fails here, by name)
            var externs = typeof(Native).GetMethods(BindingFlags.Public | BindingFlags.Static)
                .Where(m => m.GetCustomAttributes(typeof(DllImportAttribute), false).Length > 0).ToList();
            Assert.Greater(externs.Count, 40);
            foreach (var m in externs)
                Marshal.Prelink(m);
        }

        static string Pascal(string upper)
        {
            return string.Concat(upper.ToLowerInvariant().Split('_').Select(w => char.ToUpperInvariant(w[0]) + w.Substring(1)));
        }

        static string Snake(string pascal)
        {
            return Regex.Replace(pascal, "(?<=.)([A-Z])", "_$1").ToLowerInvariant();
        }

        [Test]
        public void StructLayoutsMatchTheHeader()
        {
            // Every struct of embra.h: the C compiler's sizeof and offsetof against Marshal's, field by field
            // (C# fields are the C fields in PascalCase).
            string header = File.ReadAllText(Path.Combine(Env.Source, "capi", "include", "embra", "embra.h"));
            var structs = Regex.Matches(header, @"typedef struct (embra_(\w+)) \{").Cast<Match>()
                .ToDictionary(m => m.Groups[1].Value, m => typeof(Native).Assembly.GetType("Embra." + Pascal(m.Groups[2].Value.ToUpperInvariant())));
            Assert.GreaterOrEqual(structs.Count, 20);
            var program = new List<string> { "#include <stddef.h>", "#include <stdio.h>", "#include \"embra/embra.h\"", "int main(void) {" };
            foreach (var s in structs)
            {
                Assert.IsNotNull(s.Value, "no C# struct for " + s.Key);
                program.Add("  printf(\"" + s.Key + " %zu\\n\", sizeof(" + s.Key + "));");
                foreach (var f in s.Value.GetFields(BindingFlags.Public | BindingFlags.Instance))
                    program.Add("  printf(\"" + s.Key + "." + f.Name + " %zu\\n\", offsetof(" + s.Key + ", " + Snake(f.Name) + "));");
            }
            program.Add("  return 0;\n}");
            string dir = Env.TempDir();
            File.WriteAllLines(Path.Combine(dir, "layout.c"), program);
            string build = Environment.GetEnvironmentVariable("LD_LIBRARY_PATH").Split(':')[0];  // the build tree
            Func<string, string, string> run = (file, args) =>
            {
                var start = new ProcessStartInfo(file, args) { UseShellExecute = false, RedirectStandardOutput = true };
                using (var p = Process.Start(start))
                {
                    string output = p.StandardOutput.ReadToEnd();
                    p.WaitForExit();
                    Assert.AreEqual(0, p.ExitCode, file + " " + args);
                    return output;
                }
            };
            run("cc", "-I \"" + Path.Combine(Env.Source, "capi", "include") + "\" -I \"" + Path.Combine(build, "generated") +
                "\" -o \"" + Path.Combine(dir, "layout") + "\" \"" + Path.Combine(dir, "layout.c") + "\"");
            var c = run(Path.Combine(dir, "layout"), "").Split(new[] { '\n' }, StringSplitOptions.RemoveEmptyEntries)
                .ToDictionary(line => line.Split(' ')[0], line => int.Parse(line.Split(' ')[1]));
            Directory.Delete(dir, true);
            foreach (var s in structs)
            {
                Assert.AreEqual(c[s.Key], Marshal.SizeOf(s.Value), "sizeof " + s.Key);
                foreach (var f in s.Value.GetFields(BindingFlags.Public | BindingFlags.Instance))
                    Assert.AreEqual(c[s.Key + "." + f.Name], (int)Marshal.OffsetOf(s.Value, f.Name), s.Key + "." + f.Name);
            }
        }

        [Test]
        public void DefaultsAndVersions()
        {
            var s = Library.DefaultSolverDef();
            Assert.AreEqual(SolverDef.CurrentVersion, s.Version);
            Assert.AreEqual(16, s.Substeps);
            Assert.AreEqual(1, s.ChainSolve);
            Assert.AreEqual(1.0 / 60.0, s.Dt);
            unsafe { Assert.AreEqual(-9.81, s.Gravity[2]); }
            var m = Library.DefaultMaterial();
            Assert.AreEqual(1.0, m.Density);
            Assert.AreEqual(0.5, m.FrictionStatic);
            Assert.AreEqual(ColliderDef.CurrentVersion, Native.embra_default_collider_def().Version);
            Assert.AreEqual(4, Library.ConstraintArity(ConstraintKind.Dihedral));
            Assert.AreEqual(5, Library.ConstraintArity(ConstraintKind.Conical));
            Assert.AreEqual(2, Library.ConstraintArity(ConstraintKind.LengthMin));
            Assert.AreEqual(3, Library.ConstraintArity(ConstraintKind.AngleMin));
            Assert.AreEqual(3, Library.ConstraintArity(ConstraintKind.AngleMax));
            Assert.AreEqual(3, Library.ConstraintArity(ConstraintKind.Colinear));
            Assert.AreEqual(4, Library.ConstraintArity(ConstraintKind.Direction));
            Assert.AreEqual(4, Library.ConstraintArity(ConstraintKind.Cocircular));
            Assert.AreEqual(5, Library.ConstraintArity(ConstraintKind.Cospherical));
            Assert.AreEqual(Native.AbiVersion, Library.AbiVersion);
            var parts = Library.VersionString.Split('.').Select(int.Parse).ToArray();
            Assert.AreEqual(parts[0] * 10000 + parts[1] * 100 + parts[2], Library.Version);
        }

        [Test]
        public void FreeFallIsSymplecticEulerInClosedForm()
        {
            var solver = Library.DefaultSolverDef();
            solver.Substeps = 10;
            using (var w = new World(solver))
            {
                var def = Native.embra_default_body_def();
                def.Material.Mass = 2.0;
                w.CreateBody(new[] { 0.0, 0.0, 5.0 }, def: def);
                w.Step(30);
                int n = 300;
                double h = (1.0 / 60.0) / 10;
                Assert.AreEqual(5.0 - 9.81 * h * h * n * (n + 1) / 2, w.GetPositions()[2], 1e-10);
                Assert.AreEqual(-9.81 * n * h, w.GetVelocities()[2], 1e-9);
            }
        }

        [Test]
        public void GroupsBulkConstraintsPinsCollidersAndJson()
        {
            var solver = Library.DefaultSolverDef();
            solver.Iterations = 20;
            using (var w = new World(solver))
            {
                Assert.AreNotEqual(w.DefaultGroup, w.ContactGroup);
                var links = w.CreateGroup(5, 3);
                w.SetGroupOrder(links, 4);
                w.SetGroupWeight(links, 2);
                var def = Native.embra_default_body_def();
                def.Generate = 0;
                def.Material.Mass = 0.6;
                var xyz = Enumerable.Range(0, 6).SelectMany(i => new[] { 0.1 * i, 0, 0 }).ToArray();
                var body = w.CreateBody(xyz, def: def);
                int first, count;
                w.GetBodyParticles(body.Id, out first, out count);
                Assert.AreEqual(6, count);
                Assert.AreEqual(5, w.AddConstraints(ConstraintKind.Distance, new[] { 0, 1, 1, 2, 2, 3, 3, 4, 4, 5 }, group: links));
                w.AddConstraint(ConstraintKind.Tether, new[] { 0, 5 }, 0.6, 1e-3, links);
                var pin = w.CreatePin(0, new double[] { 0, 0, 0 });
                w.SetPinTarget(pin, new[] { 0.0, 0.0, 0.25 });
                CollectionAssert.AreEqual(new[] { 0.0, 0.0, 0.25 }, w.PinTarget(pin));
                var floor = Native.embra_default_collider_def();
                floor.Shape = (int)ColliderShape.Plane;
                unsafe { floor.Position[2] = -0.3; }
                var c = w.CreateCollider(floor);
                w.SetColliderTransform(c, new[] { 0.0, 0.0, -0.35 }, new[] { 1.0, 0, 0, 0 });
                w.Step(120);
                var p = w.GetPositions();
                for (int i = 0; i < 5; ++i)
                {
                    double dx = p[3 * i + 3] - p[3 * i], dy = p[3 * i + 4] - p[3 * i + 1], dz = p[3 * i + 5] - p[3 * i + 2];
                    Assert.AreEqual(0.1, Math.Sqrt(dx * dx + dy * dy + dz * dz), 1e-6);
                }
                Assert.That(Enumerable.Range(0, 6).All(i => p[3 * i + 2] >= -0.35 - 1e-9));  // above the floor
                Assert.Less(w.GroupReport(links).ResidualMax, 1e-6);
                Assert.AreEqual(-1, w.Warning.Frame);
                w.SetRestScale(body.Id, 1.0);
                string json = w.SaveJson();
                string file = Path.Combine(Env.TempDir(), "mid.json");
                w.SaveFile(file);
                using (var a = World.LoadJson(json))
                using (var b = World.LoadFile(file))
                {
                    w.Step(10); a.Step(10); b.Step(10);
                    Env.AssertBitIdentical(w.GetPositions(), a.GetPositions());
                    Env.AssertBitIdentical(w.GetPositions(), b.GetPositions());
                }
                w.DestroyCollider(c);
                w.DestroyGroup(links);
                Assert.AreEqual(0, w.Counts.Constraints);
                w.SetVelocities(new double[] { 1, 2, 3 }, 5);
                CollectionAssert.AreEqual(new double[] { 1, 2, 3 }, w.GetVelocities(5, 1));
                var s = w.Solver;
                s.Substeps = 7;
                w.Solver = s;
                Assert.AreEqual(7, w.Solver.Substeps);
            }
        }

        [Test]
        public void ComponentHangsAClothAndReportsErrors()
        {
            // A 5 x 5 quad net, two corners anchored, a weight-5 length goal across the bottom edge.
            var vertices = new List<Point3d>();
            for (int i = 0; i < 5; ++i)
                for (int j = 0; j < 5; ++j) vertices.Add(new Point3d(0.25 * j, 0, -0.25 * i));
            var faces = new List<MeshFace>();
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) faces.Add(new MeshFace(5 * i + j, 5 * i + j + 1, 5 * i + j + 6, 5 * i + j + 5));
            var goals = new List<Goal> { Goal.Length(20, 24, 0.5, 0, 5), Goal.Angle(0, 1, 5) };
            using (var component = new FormFindingComponent())
            {
                Assert.AreEqual(17, component.Inputs.Count);  // the last is Mesh, instead of Vertices and Faces
                var da = new DataAccess().Set(0, vertices).Set(1, faces).Set(2, new List<int> { 0, 4 }).Set(4, goals)
                    .Set(FormFindingComponent.InIterations, 4).Set(FormFindingComponent.InStepsPerSolve, 30)
                    .Set(FormFindingComponent.InReset, true).Set(FormFindingComponent.InRun, false);
                component.ComputeData(da);
                Assert.IsEmpty(component.RuntimeMessages);
                var e0 = da.GetList<double>(FormFindingComponent.OutGoalErrors);
                Assert.AreEqual(0.5, e0[0], 1e-12);  // 1 m apart, asked for 0.5 m
                Assert.AreEqual(0.0, e0[1], 1e-12);  // measured from the input: met
                da.Set(FormFindingComponent.InReset, false).Set(FormFindingComponent.InRun, true);
                for (int k = 0; k < 4; ++k) component.ComputeData(da);
                Assert.AreEqual(120, da.Get<int>(FormFindingComponent.OutFrame));
                var e1 = da.GetList<double>(FormFindingComponent.OutGoalErrors);
                Assert.Less(e1[0], 1e-3);
                var anchors = da.GetList<double>(FormFindingComponent.OutAnchorErrors);
                Assert.That(anchors.All(a => a == 0.0));
                var before = component.PositionsXyz();

                // A NaN vertex on reset: the component shows the C message, keeps its world, never throws.
                var bad = new List<Point3d>(vertices);
                bad[7] = new Point3d(double.NaN, 0, 0);
                da.Set(0, bad).Set(FormFindingComponent.InReset, true).Set(FormFindingComponent.InRun, false);
                component.ComputeData(da);
                Assert.AreEqual(1, component.RuntimeMessages.Count);
                Assert.AreEqual(GH_RuntimeMessageLevel.Error, component.RuntimeMessages[0].Key);
                StringAssert.StartsWith("embra_body_create: ", component.RuntimeMessages[0].Value);
                Env.AssertBitIdentical(before, component.PositionsXyz());

                // An anchor out of range: the same, with the index named.
                da.Set(0, vertices).Set(2, new List<int> { 0, 99 });
                component.ComputeData(da);
                StringAssert.Contains("99", component.RuntimeMessages[0].Value);
                Env.AssertBitIdentical(before, component.PositionsXyz());
            }
        }
    }

    /// <summary>A scene's OBJ paths resolve against its folder (the file's for LoadFile, baseDir for LoadJson)
    /// and may not leave it unless the host allows it (allowPathsOutsideBase).</summary>
    [TestFixture]
    public class LoadOptionsTests
    {
        const string Obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n";  // one quad: 4 vertices

        static string Scene(string obj)
        {
            return "{\"format\": \"embra-scene\", \"version\": 1, \"name\": \"obj_scene\", \"bodies\": [{\"name\": \"sheet\", " +
                   "\"mesh\": {\"obj\": \"" + obj.Replace("\\", "\\\\") + "\"}, \"material\": {\"mass\": 0.5}}]}";
        }

        string root, scenes;

        [SetUp]
        public void Folders()
        {
            root = Env.TempDir();
            scenes = Path.Combine(root, "scenes");
            Directory.CreateDirectory(scenes);
            File.WriteAllText(Path.Combine(root, "outside.obj"), Obj);
            File.WriteAllText(Path.Combine(scenes, "inside.obj"), Obj);
            File.WriteAllText(Path.Combine(scenes, "inside.json"), Scene("inside.obj"));
            File.WriteAllText(Path.Combine(scenes, "outside.json"), Scene("../outside.obj"));
            File.WriteAllText(Path.Combine(scenes, "absolute.json"), Scene(Path.Combine(root, "outside.obj")));
        }

        [TearDown]
        public void Remove() { Directory.Delete(root, true); }

        static int Particles(World w)
        {
            using (w) return w.Counts.Particles;
        }

        [Test]
        public void ObjPathsResolveAgainstTheScenesFolder()
        {
            string cwd = Environment.CurrentDirectory;
            Environment.CurrentDirectory = root;  // not the scene's folder
            try
            {
                Assert.AreEqual(4, Particles(World.LoadFile(Path.Combine(scenes, "inside.json"))));
                Assert.AreEqual(4, Particles(World.LoadJson(File.ReadAllText(Path.Combine(scenes, "inside.json")), scenes)));
                Assert.AreEqual(4, Particles(World.LoadFile(Path.Combine("scenes", "inside.json"), allowPathsOutsideBase: true)));
            }
            finally { Environment.CurrentDirectory = cwd; }
        }

        [TestCase("outside.json", "../outside.obj")]
        [TestCase("absolute.json", null)]
        public void ObjPathsOutOfTheScenesFolderAreRefusedUnlessAllowed(string name, string obj)
        {
            obj = obj ?? Path.Combine(root, "outside.obj");
            string file = Path.Combine(scenes, name), text = File.ReadAllText(file);
            var e = Assert.Catch<Exception>(() => World.LoadFile(file));
            Assert.IsInstanceOf<IEmbraException>(e);
            StringAssert.StartsWith("embra_world_load_file: ", e.Message);
            StringAssert.Contains(obj, e.Message);
            e = Assert.Catch<Exception>(() => World.LoadJson(text, scenes));
            Assert.IsInstanceOf<IEmbraException>(e);
            StringAssert.StartsWith("embra_world_load_json_with_options: ", e.Message);
            StringAssert.Contains(obj, e.Message);
            // the host that trusts the scene says so
            Assert.AreEqual(4, Particles(World.LoadFile(file, allowPathsOutsideBase: true)));
            Assert.AreEqual(4, Particles(World.LoadJson(text, scenes, allowPathsOutsideBase: true)));
            Assert.Throws<FileNotFoundException>(() => World.LoadFile(Path.Combine(scenes, "missing.json"), true));
            var o = Native.embra_default_load_options();
            Assert.AreEqual(LoadOptions.CurrentVersion, o.Version);
            Assert.AreEqual(0, o.AllowPathsOutsideBase);
            Assert.AreEqual(IntPtr.Zero, o.BaseDir);
        }
    }

    [TestFixture]
    public class FieldTests
    {
        const int Frames = 40;

        static string Example(string name) { return Path.Combine(Env.Source, "examples", name + ".json"); }

        /// <summary>The scene file's text without its "fields" array (each field an object without braces inside).</summary>
        static string WithoutFields(string name)
        {
            string json = File.ReadAllText(Example(name));
            string stripped = Regex.Replace(json, @",\s*""fields""\s*:\s*\[\s*\{[^{}]*\}\s*\]", "");
            Assert.AreNotEqual(json, stripped, name + ": no fields to strip");
            return stripped;
        }

        /// <summary>The scene without its fields, loaded here, given its field by `addField` and stepped:
        /// bit for bit what `embra run` gives for the whole scene; without the field it is not.</summary>
        static void CheckAgainstCHost(string name, Func<World, FieldId> addField)
        {
            StringAssert.DoesNotContain("\"actions\"", File.ReadAllText(Example(name)));  // `embra run` steps as Step does
            double[] c = Env.Cli("run", Example(name), "--frames", Frames.ToString());
            using (var w = World.LoadJson(WithoutFields(name)))
            {
                Assert.AreEqual(0, w.FieldCount);
                addField(w);
                Assert.AreEqual(1, w.FieldCount);
                w.Step(Frames);
                Env.AssertBitIdentical(c, w.GetPositions());
            }
            using (var w = World.LoadJson(WithoutFields(name)))
            {
                w.Step(Frames);
                double[] still = w.GetPositions();
                Assert.AreEqual(c.Length, still.Length);
                Assert.IsFalse(c.Select(BitConverter.DoubleToInt64Bits).SequenceEqual(still.Select(BitConverter.DoubleToInt64Bits)));
            }
        }

        [Test]
        public void FlagInWindMadeInCSharpMatchesTheCHostBitForBit()
        {
            CheckAgainstCHost("flag_wind", w =>
            {
                var def = Library.DefaultWindDef();
                unsafe
                {
                    def.Direction[0] = 1;
                    def.Direction[1] = 0.3;
                    def.Direction[2] = 0;
                }
                def.Speed = 6.0;
                def.AirDensity = 1.2;
                def.Drag = 1.0;
                def.Lift = 1.0;
                return w.CreateWind(def);
            });
        }

        [Test]
        public void SoapFilmMadeInCSharpMatchesTheCHostBitForBit()
        {
            CheckAgainstCHost("minimal_surface", w =>
            {
                var def = Library.DefaultSurfaceTensionDef();
                def.Body = new BodyId { Index = 0, Generation = 1 };  // "film", the scene's first body
                def.Tension = 1.0;
                def.Regularisation = 1.0;
                return w.CreateSurfaceTension(def);
            });
        }

        [Test]
        public void TorsionFieldMadeInCSharpMatchesTheCHostBitForBit()
        {
            CheckAgainstCHost("interacting_elements", w =>
            {
                var def = Library.DefaultVortexDef();
                unsafe { def.Axis[2] = 1; }
                def.Strength = 12.0;
                def.Radius = 0.8;
                def.Twist = 2.0;
                def.Decay = 1.5;
                return w.CreateVortex(def);
            });
        }

        static readonly double[] Octahedron = { 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1 };
        static readonly int[] OctahedronTriangles = { 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5 };

        static World OctahedronWorld(out Body body)
        {
            var s = Library.DefaultSolverDef();
            unsafe { s.Gravity[2] = 0; }
            s.Substeps = 4;
            var w = new World(s);
            var def = Library.DefaultBodyDef();
            def.Material.Mass = 1.0;
            def.Material.StretchCompliance = 1e-2;
            def.Generate = (int)Generate.Stretch;
            body = w.CreateBody(Octahedron, OctahedronTriangles, def: def);
            return w;
        }

        static double Volume(double[] x)
        {
            double v = 0;
            for (int t = 0; t < OctahedronTriangles.Length; t += 3)
            {
                int a = 3 * OctahedronTriangles[t], b = 3 * OctahedronTriangles[t + 1], c = 3 * OctahedronTriangles[t + 2];
                v += (x[a] * (x[b + 1] * x[c + 2] - x[b + 2] * x[c + 1]) - x[a + 1] * (x[b] * x[c + 2] - x[b + 2] * x[c]) +
                      x[a + 2] * (x[b] * x[c + 1] - x[b + 1] * x[c])) / 6.0;
            }
            return v;
        }

        [Test]
        public void PressureInflatesAClosedSurfaceAndKeepVolumeHoldsIt()
        {
            const double rest = 4.0 / 3.0;  // the unit octahedron
            Body body;
            using (var w = OctahedronWorld(out body))
            {
                Assert.AreEqual(rest, Volume(w.GetPositions()), 1e-15);
                var def = Library.DefaultPressureDef();
                def.Body = body.Id;
                def.InsidePressure = 50.0;
                def.OutsidePressure = 10.0;
                w.CreatePressure(def);
                w.Step(30);
                Assert.Greater(Volume(w.GetPositions()), 1.05 * rest);
            }
            using (var w = OctahedronWorld(out body))
            {
                var def = Library.DefaultPressureDef();
                def.Body = body.Id;
                def.InsidePressure = 50.0;
                def.OutsidePressure = 10.0;
                def.KeepVolume = 1;
                w.CreatePressure(def);
                w.Step(30);
                Assert.AreEqual(rest, Volume(w.GetPositions()), 1e-4 * rest);  // the free one grew by over 5%
            }
        }

        [Test]
        public void DefaultsAreTheDocumentedOnes()
        {
            var wind = Library.DefaultWindDef();
            Assert.AreEqual(WindDef.CurrentVersion, wind.Version);
            unsafe { Assert.AreEqual(new[] { 1.0, 0.0, 0.0 }, new[] { wind.Direction[0], wind.Direction[1], wind.Direction[2] }); }
            Assert.AreEqual(new[] { 0.0, 1.2, 1.0, 1.0 }, new[] { wind.Speed, wind.AirDensity, wind.Drag, wind.Lift });
            Assert.AreEqual(new BodyId(), wind.Body);
            var pressure = Library.DefaultPressureDef();
            Assert.AreEqual(PressureDef.CurrentVersion, pressure.Version);
            Assert.AreEqual(0, pressure.KeepVolume);
            Assert.AreEqual(new[] { 0.0, 0.0, 0.0, 0.0 },
                            new[] { pressure.InsidePressure, pressure.OutsidePressure, pressure.VolumeCompliance, pressure.RestVolume });
            var tension = Library.DefaultSurfaceTensionDef();
            Assert.AreEqual(SurfaceTensionDef.CurrentVersion, tension.Version);
            Assert.AreEqual(new[] { 0.0, 1.0 }, new[] { tension.Tension, tension.Regularisation });
            var vortex = Library.DefaultVortexDef();
            Assert.AreEqual(VortexDef.CurrentVersion, vortex.Version);
            unsafe { Assert.AreEqual(new[] { 0.0, 0.0, 1.0 }, new[] { vortex.Axis[0], vortex.Axis[1], vortex.Axis[2] }); }
            Assert.AreEqual(new[] { 0.0, 1.0, 0.0, 0.0, 0.0 },
                            new[] { vortex.Strength, vortex.Radius, vortex.Twist, vortex.Decay, vortex.StartTime });
        }

        [Test]
        public void DestroyedFieldStopsActingAndItsIdIsStale()
        {
            Body body;
            using (var w = OctahedronWorld(out body))
            {
                var vortex = Library.DefaultVortexDef();
                vortex.Strength = 3.0;
                var field = w.CreateVortex(vortex);
                var wind = Library.DefaultWindDef();
                wind.Body = body.Id;
                wind.Speed = 2.0;
                var other = w.CreateWind(wind);
                Assert.AreEqual(2, w.FieldCount);
                Assert.AreNotEqual(field, other);
                w.DestroyField(field);
                Assert.AreEqual(1, w.FieldCount);
                var stale = Assert.Throws<EmbraInvalidOperationException>(() => w.DestroyField(field));
                Assert.AreEqual(Status.StaleId, stale.Status);
                StringAssert.StartsWith("embra_field_destroy: ", stale.Message);
                Assert.AreEqual(Errors.LastMessage(), stale.Message);
                Assert.AreEqual(1, w.FieldCount);
                w.DestroyField(other);
                Assert.AreEqual(0, w.FieldCount);
                double[] before = w.GetPositions();
                w.Step(5);  // no field, no gravity, at rest: nothing moves
                Env.AssertBitIdentical(before, w.GetPositions());
            }
        }

        static string Snapshot(World w)
        {
            var bits = w.GetPositions().Concat(w.GetVelocities()).Select(v => BitConverter.DoubleToInt64Bits(v).ToString("x"));
            return string.Join(",", bits) + "|" + w.FieldCount + "|" + w.SaveJson();
        }

        [Test]
        public void RefusedFieldCallsThrowTheCMessageAndChangeNothing()
        {
            Body body;
            using (var w = OctahedronWorld(out body))
            {
                var breeze = Library.DefaultWindDef();
                breeze.Body = body.Id;
                breeze.Speed = 1.0;
                w.CreateWind(breeze);
                w.Step(3);
                string before = Snapshot(w);

                var wind = Library.DefaultWindDef();
                wind.Version = 99;
                var v = Assert.Throws<EmbraInvalidOperationException>(() => w.CreateWind(wind));
                Assert.AreEqual(Status.Version, v.Status);
                StringAssert.StartsWith("embra_wind_create: ", v.Message);
                StringAssert.Contains("99", v.Message);
                Assert.AreEqual(Errors.LastMessage(), v.Message);
                wind = Library.DefaultWindDef();
                wind.Speed = double.NaN;
                var nan = Assert.Throws<EmbraArgumentException>(() => w.CreateWind(wind));
                Assert.That(nan, Is.InstanceOf<ArgumentException>());
                StringAssert.StartsWith("embra_wind_create: ", nan.Message);
                var still = Library.DefaultWindDef();
                unsafe { still.Direction[0] = 0; }
                var zero = still;  // a copy the lambda may capture (a fixed buffer's owner may not be)
                Assert.Throws<EmbraArgumentException>(() => w.CreateWind(zero));

                var pressure = Library.DefaultPressureDef();
                pressure.Body = body.Id;
                pressure.InsidePressure = double.NaN;
                var p = Assert.Throws<EmbraArgumentException>(() => w.CreatePressure(pressure));
                StringAssert.StartsWith("embra_pressure_create: ", p.Message);
                pressure.InsidePressure = 0;
                pressure.KeepVolume = 2;
                Assert.Throws<EmbraArgumentException>(() => w.CreatePressure(pressure));
                Assert.Throws<EmbraArgumentException>(() => w.CreatePressure(Library.DefaultPressureDef()));  // no body

                var tension = Library.DefaultSurfaceTensionDef();
                tension.Body = body.Id;
                tension.Tension = -1.0;
                var t = Assert.Throws<EmbraArgumentException>(() => w.CreateSurfaceTension(tension));
                StringAssert.StartsWith("embra_surface_tension_create: ", t.Message);
                var vortex = Library.DefaultVortexDef();
                vortex.Radius = 0.0;
                var r = Assert.Throws<EmbraArgumentException>(() => w.CreateVortex(vortex));
                StringAssert.StartsWith("embra_vortex_create: ", r.Message);

                var missing = new BodyId { Index = 7, Generation = 1 };  // out of range: no such body
                wind = Library.DefaultWindDef();
                wind.Body = missing;
                pressure = Library.DefaultPressureDef();
                pressure.Body = missing;
                tension = Library.DefaultSurfaceTensionDef();
                tension.Body = missing;
                vortex = Library.DefaultVortexDef();
                vortex.Body = missing;
                var calls = new Dictionary<string, TestDelegate>
                {
                    { "embra_wind_create: ", () => w.CreateWind(wind) },
                    { "embra_pressure_create: ", () => w.CreatePressure(pressure) },
                    { "embra_surface_tension_create: ", () => w.CreateSurfaceTension(tension) },
                    { "embra_vortex_create: ", () => w.CreateVortex(vortex) },
                    { "embra_field_destroy: ", () => w.DestroyField(new FieldId { Index = 5, Generation = 1 }) },
                };
                foreach (var call in calls)
                {
                    var stale = Assert.Throws<EmbraInvalidOperationException>(call.Value);
                    Assert.AreEqual(Status.StaleId, stale.Status, call.Key);
                    StringAssert.StartsWith(call.Key, stale.Message);
                }
                Assert.AreEqual(before, Snapshot(w));
                w.Dispose();
                Assert.Throws<EmbraObjectDisposedException>(() => w.FieldCount.ToString());
            }
        }
    }
    // Edits without a rebuild: a particle of mass m hanging on a link of compliance c rests stretched
    // m g c, and after each edit where the new value puts it; a disabled group steps to the bits of a world
    // without its constraint; the saved scene changes in the edited value only; refusals change nothing.
    public class EditTests
    {
        const double G = 9.81;

        static World Hanging(out Body b, double damping = 6.0)
        {
            var s = Library.DefaultSolverDef();
            s.Damping = damping;
            s.SettleSpeed = 1e-7;
            s.Tethers = 0;
            var w = new World(s);
            b = w.CreateBody(new[] { 0.0, 0.0, 0.0, 0.0, 0.0, -1.0 }, masses: new[] { 0.0, 2.0 });
            return w;
        }

        static double Drop(World w, Body b)
        {
            var r = w.Solve(SolveUntil.Settled, 3000);
            Assert.AreEqual((int)Solve.SettledWithinTolerance, r.Outcome);
            return -w.GetPositions()[3 * (b.First + 1) + 2] - 1.0;
        }

        /// <summary>The one differing stretch of two texts is a single number in each.</summary>
        static bool OnlyOneNumberDiffers(string a, string b)
        {
            int p = 0, s = 0;
            while (p < a.Length && p < b.Length && a[p] == b[p]) ++p;
            while (s < a.Length - p && s < b.Length - p && a[a.Length - 1 - s] == b[b.Length - 1 - s]) ++s;
            Func<string, bool> number = t => t.Length > 0 && t.All(c => "0123456789.eE+-".IndexOf(c) >= 0);
            return number(a.Substring(p, a.Length - p - s)) && number(b.Substring(p, b.Length - p - s));
        }

        [Test]
        public void ComplianceAndRestEditsMoveTheRestState()
        {
            Body b;
            using (var w = Hanging(out b))
            {
                var none = default(GroupId);
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 }, 1.0, 1e-3);
                Assert.AreEqual(2.0 * G * 1e-3, Drop(w, b), 1e-6);
                string before = w.SaveJson();
                var xyz = w.GetPositions();
                w.SetConstraintCompliance(none, ConstraintKind.Distance, 0, 4e-3);
                CollectionAssert.AreEqual(xyz, w.GetPositions());
                Assert.IsTrue(OnlyOneNumberDiffers(before, w.SaveJson()));
                Assert.AreEqual(4e-3, w.Constraint(none, ConstraintKind.Distance, 0).Compliance);
                Assert.AreEqual(2.0 * G * 4e-3, Drop(w, b), 1e-6);
                w.SetConstraintRest(none, ConstraintKind.Distance, 0, 1.5);
                Assert.AreEqual(2.0 * G * 4e-3, Drop(w, b) - 0.5, 1e-6);
                int count, generated;
                w.ConstraintCount(none, ConstraintKind.Distance, out count, out generated);
                Assert.AreEqual(1, count);
                Assert.AreEqual(0, generated);
                var e = Assert.Throws<EmbraArgumentException>(() => w.SetConstraintCompliance(none, ConstraintKind.Distance, 1, 0.0));
                StringAssert.Contains("outside [0, 1)", e.Message);
            }
        }

        [Test]
        public void PlasticityKeepsASetAndRuptureBreaksWithAnEvent()
        {
            // Elastic strain under the weight m g c / L = 0.0196, past a yield of 0.01: the rest grows
            // to m g c / 0.01 (approached from below, by 1 / (1 + yield) a frame), the elastic part m g c.
            Body b;
            var none = default(GroupId);
            using (var w = Hanging(out b))
            {
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 }, 1.0, 1e-3);
                Assert.AreEqual((0.0, 0.0), w.ConstraintPlasticity(none, ConstraintKind.Distance, 0));
                w.SetConstraintPlasticity(none, ConstraintKind.Distance, 0, 0.01, 0.0);
                Assert.AreEqual((0.01, 0.0), w.ConstraintPlasticity(none, ConstraintKind.Distance, 0));
                double d = Drop(w, b);
                double rest = w.Constraint(none, ConstraintKind.Distance, 0).Rest;
                Assert.AreEqual(2.0 * G * 1e-3 / 0.01, rest, 1e-5 * rest);
                Assert.AreEqual(2.0 * G * 1e-3, 1.0 + d - rest, 1e-6);
                Assert.AreEqual(0, w.Broken().Length);
                Assert.Throws<EmbraArgumentException>(() => w.SetConstraintPlasticity(none, ConstraintKind.Tether, 0, 0.01, 0.0));
            }
            using (var w = Hanging(out b))
            {
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 }, 1.0, 1e-3);
                w.SetConstraintPlasticity(none, ConstraintKind.Distance, 0, 0.0, 0.015);
                w.Step(60);
                var events = w.Broken();
                Assert.AreEqual(1, events.Length);
                Assert.AreEqual((int)ConstraintKind.Distance, events[0].Kind);
                Assert.AreEqual(0, events[0].Index);
                unsafe
                {
                    BrokenConstraint e = events[0];
                    Assert.AreEqual(b.First, e.Particles[0]);
                    Assert.AreEqual(b.First + 1, e.Particles[1]);
                }
                Assert.Greater(events[0].Strain, 0.015);
                Assert.AreEqual(0, w.Broken().Length);
            }
        }

        [Test]
        public void ADisabledGroupStepsLikeNoConstraint()
        {
            Body b, fb;
            using (var w = Hanging(out b, 0.0))
            using (var free = Hanging(out fb, 0.0))
            {
                var g = w.CreateGroup();
                w.AddConstraint(ConstraintKind.Distance, new[] { b.First, b.First + 1 }, group: g);
                w.SetGroupEnabled(g, false);
                Assert.IsFalse(w.GroupEnabled(g));
                w.Step(20);
                free.Step(20);
                CollectionAssert.AreEqual(free.GetPositions(), w.GetPositions());
                CollectionAssert.AreEqual(free.GetVelocities(), w.GetVelocities());
                StringAssert.Contains("\"enabled\": false", w.SaveJson());
                Assert.Throws<EmbraArgumentException>(() => w.SetGroupEnabled(w.ContactGroup, false));
                var h = w.CreateGroup();
                Assert.AreEqual(0, w.SetConstraintGroup(g, ConstraintKind.Distance, 0, h));
                w.RemoveConstraint(h, ConstraintKind.Distance, 0);
                int count, generated;
                w.ConstraintCount(h, ConstraintKind.Distance, out count, out generated);
                Assert.AreEqual(0, count);
            }
        }

        /// <summary>A world of one body: an immovable particle at the origin and one of `mass` 1 m below it, on
        /// the body's edge of stretch compliance `compliance` (damping 6/s, no tethers).</summary>
        static World HangingPair(double mass, double compliance, out Body b)
        {
            var s = Library.DefaultSolverDef();
            s.Damping = 6.0;
            s.SettleSpeed = 1e-7;
            s.Tethers = 0;
            var w = new World(s);
            var def = Library.DefaultBodyDef();
            def.Material.StretchCompliance = compliance;
            b = w.CreateBody(new[] { 0.0, 0.0, 0.0, 0.0, 0.0, -1.0 }, edges: new[] { 0, 1 }, masses: new[] { 0.0, mass }, def: def);
            return w;
        }

        [Test]
        public void AMaterialEditMovesTheGeneratedStretch()
        {
            Body b;
            using (var w = HangingPair(2.0, 1e-3, out b))
            {
                Assert.AreEqual(2.0 * G * 1e-3, Drop(w, b), 1e-6);
                Assert.Throws<EmbraArgumentException>(() => w.SetConstraintCompliance(default(GroupId), ConstraintKind.Distance, 0, 0.0));
                var m = w.GetMaterial(b.Id);
                m.StretchCompliance = 3e-3;
                string before = w.SaveJson();
                w.SetMaterial(b.Id, m);
                Assert.IsTrue(OnlyOneNumberDiffers(before, w.SaveJson()));
                Assert.AreEqual(2.0 * G * 3e-3, Drop(w, b), 1e-6);
                m.Mass = 5.0;
                var e = Assert.Throws<EmbraArgumentException>(() => w.SetMaterial(b.Id, m));
                StringAssert.Contains("mass", e.Message);
            }
        }

        /// <summary>Masses set on a running world: a particle hung on a link of compliance 2e-3 m/N rests
        /// m g c lower for the new mass; the saved scene differs at that mass only and the world loaded from
        /// it steps on to the same bits; refusals (count, sign, non-finite, stale body) change nothing.</summary>
        [Test]
        public void MassesSetWithoutARebuild()
        {
            Body b;
            using (var w = HangingPair(1.0, 2e-3, out b))
            {
                Assert.AreEqual(1.0 * G * 2e-3, Drop(w, b), 1e-6);
                CollectionAssert.AreEqual(new[] { 0.0, 1.0 }, w.GetBodyMasses(b.Id));
                string before = w.SaveJson();
                w.SetBodyMasses(b.Id, new[] { 0.0, 3.5 });
                string saved = w.SaveJson();
                Assert.IsTrue(OnlyOneNumberDiffers(before, saved));
                CollectionAssert.AreEqual(new[] { 0.0, 3.5 }, w.GetBodyMasses(b.Id));
                using (var loaded = World.LoadJson(saved))
                {
                    for (int k = 0; k < 40; ++k)
                    {
                        w.Step();
                        loaded.Step();
                    }
                    Env.AssertBitIdentical(w.GetPositions(), loaded.GetPositions());
                    Env.AssertBitIdentical(w.GetVelocities(), loaded.GetVelocities());
                }
                Assert.AreEqual(3.5 * G * 2e-3, Drop(w, b), 1e-6);

                string text = w.SaveJson();
                foreach (var bad in new[] { new[] { 0.0 }, new[] { 0.0, 1.0, 1.0 }, new[] { 0.0, -1.0 }, new[] { 0.0, double.NaN },
                                            new[] { 0.0, double.PositiveInfinity }, new[] { 0.0, 1e-310 } })
                    Assert.Throws<EmbraArgumentException>(() => w.SetBodyMasses(b.Id, bad));
                var refused = Assert.Throws<EmbraArgumentException>(() => w.SetBodyMasses(b.Id, null));
                StringAssert.Contains("masses", refused.Message);
                var stale = b.Id;
                stale.Index += 4;
                Assert.Throws<EmbraInvalidOperationException>(() => w.SetBodyMasses(stale, new[] { 0.0, 1.0 }));
                Assert.AreEqual(text, w.SaveJson());
            }
        }

        [Test]
        public void AVortexEditedBetweenSteps()
        {
            using (var w = new World())
            {
                w.SetGravity(0.0, 0.0, 0.0);
                w.CreateBody(new[] { 0.5, 0.0, 0.0 });
                var f = w.CreateVortex(Library.DefaultVortexDef());
                w.Step();
                Assert.AreEqual(0.0, w.GetPositions()[1]);
                var v = w.GetVortex(f);
                v.Strength = 2.0;
                w.SetVortex(f, v);
                Assert.AreEqual(2.0, w.GetVortex(f).Strength);
                w.Step();
                double a = 2.0 * Math.Exp(-0.25) * 0.5;
                Assert.AreEqual(a / 60, w.GetVelocities()[1], 1e-3 * a / 60);
                string before = w.SaveJson();
                Assert.Throws<EmbraArgumentException>(() => w.SetWind(f, Library.DefaultWindDef()));
                v.Radius = 0.0;
                Assert.Throws<EmbraArgumentException>(() => w.SetVortex(f, v));
                Assert.AreEqual(before, w.SaveJson());
            }
        }
    }
}
