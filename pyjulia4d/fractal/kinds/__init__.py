"""The kinds of set, host side: one module each, named by the registry's kind entry
(fractal/registry.py Kind.host, read through kind_hooks), with

- ``defines(scene)``: the kind's -D switches (its piece, kernels/kind/<name>.cl, reads them);
- ``set_radius(scene)``: the radius of a ball about the origin that provably holds the set;
- ``check(scene)``: the kind's own rules, each failure one SceneError naming the key to change.

Its float64 twin is reference/kind/<name>.py.  Adding a kind is a registry entry, its piece,
its module here and its twin; nothing else branches on the kind's name.
"""
