// The C# consumer of an installed embra (lib/Embra.Net.dll beside libembra.so): the free fall of
// consumer.c, checked against the same closed form. Prints "consumer ok" when it agrees.
using System;

static class Consumer
{
    static int Main()
    {
        var solver = Embra.Library.DefaultSolverDef();
        solver.Substeps = 10;
        double[] p;
        using (var world = new Embra.World(solver))
        {
            var def = Embra.Native.embra_default_body_def();
            def.Material.Mass = 1.0;
            var body = world.CreateBody(new[] { 0.0, 0.0, 5.0 }, def: def);
            world.Step(30);
            p = world.GetPositions(body.First, 1);
        }
        int n = 300;
        double h = (1.0 / 60.0) / 10, expected = 5.0 - 9.81 * h * h * n * (n + 1) / 2.0;
        Console.WriteLine("embra " + Embra.Library.VersionString + ": z = " + p[2].ToString("R") + ", closed form " + expected.ToString("R"));
        if (!(Math.Abs(p[2] - expected) < 1e-10 && p[0] == 0.0 && p[1] == 0.0)) return 1;
        Console.WriteLine("consumer ok");
        return 0;
    }
}
