// The C ABI of libembra as P/Invoke sees it. Status codes, limits, enums, structs and one extern per
// function are generated from capi/include/embra/embra.h into NativeGenerated.cs by
// scripts/gen_bindings.py (run it after changing the header; the test bindings.fresh fails while a
// generated file is stale). This part names the library the externs bind to.
using System.Runtime.InteropServices;

namespace Embra
{
    /// <summary>The prototypes, one per exported function of embra.h (NativeGenerated.cs). The world is
    /// passed as a raw pointer: <see cref="World"/> holds it in a SafeHandle and keeps it alive across each
    /// call.</summary>
    public static partial class Native
    {
        public const string Library = "embra";  // libembra.so: the assembly's folder, LD_LIBRARY_PATH, the system
        const CallingConvention C = CallingConvention.Cdecl;
    }
}
