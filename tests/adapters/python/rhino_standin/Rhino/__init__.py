"""A stand-in for RhinoCommon's Rhino package: only the Rhino.Geometry members the Grasshopper example
(host_adapters/python/examples/grasshopper_hanging_mesh.py) calls, so it runs here without Rhino."""
