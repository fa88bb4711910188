"""Firmware in the loop: the DSP56800E intrinsics and the seed firmware compiled for the host, C
generation for any platform, the compiled controller tick in the Drake diagram, and checks of a user's C.

- :mod:`.build`     find a compiler (cc/gcc/clang, else ``zig cc``), build and cache shared libraries, cffi
- :mod:`.host`      the intrinsics and tp17.C compiled: batch calls from numpy
"""
