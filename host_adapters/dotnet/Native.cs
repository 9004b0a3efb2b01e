// The C ABI of libembra as P/Invoke sees it. Status codes, limits, enums, structs and one extern per
// function are generated from capi/include/embra/embra.h into NativeGenerated.cs by
// scripts/gen_bindings.py (run it after changing the header; the test bindings.fresh fails while a
// generated file is stale). This part names the library the externs bind to.
using System;
using System.IO;
using System.Runtime.InteropServices;

namespace Embra
{
    /// <summary>The prototypes, one per exported function of embra.h (NativeGenerated.cs). The world is
    /// passed as a raw pointer: <see cref="World"/> holds it in a SafeHandle and keeps it alive across each
    /// call.</summary>
    public static partial class Native
    {
        // embra.dll on Windows, libembra.so elsewhere: the assembly's folder, LD_LIBRARY_PATH, the system
        public const string Library = "embra";
        const CallingConvention C = CallingConvention.Cdecl;

        /// <summary>On Windows, embra.dll beside this assembly (a plug-in's folder) is loaded before the
        /// first call: Windows itself searches the program's folder (Rhino's), the system folders and PATH,
        /// and every [DllImport] of a module already loaded binds to it. Elsewhere nothing is needed.</summary>
        static Native()
        {
            if (Environment.OSVersion.Platform != PlatformID.Win32NT) return;
            string folder = Path.GetDirectoryName(typeof(Native).Assembly.Location);
            if (string.IsNullOrEmpty(folder)) return;
            string beside = Path.Combine(folder, "embra.dll");
            if (File.Exists(beside)) LoadLibraryW(beside);
        }

        [DllImport("kernel32", CharSet = CharSet.Unicode, SetLastError = true)]
        static extern IntPtr LoadLibraryW(string path);
    }
}
