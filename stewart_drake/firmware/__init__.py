"""Firmware in the loop: the DSP56800E intrinsics and the seed firmware compiled for the host, C
generation for any platform, the compiled controller tick as a control law, and checks of a user's C.

- :mod:`.build`     find a compiler (``$STEWART_DRAKE_CC``, cc/gcc/clang, else the ziglang wheel's ``zig cc``),
                    build shared libraries, cache them by content hash (``$STEWART_DRAKE_CACHE``), load with cffi
- :mod:`.host`      ``fixedpoint/c``: the intrinsics (``intrinsic``, ``frac``) and tp17.C (``tp17_leg_lengths_c``,
                    ``op_counts_tp17``) compiled, batch calls from numpy
- :mod:`.generate`  ``generate(platform, config) -> GeneratedFirmware``: sd_firmware.h/.c + README, op counts, cycles
- :mod:`.module`    ``compile_generated`` / ``compile_user`` -> ``FirmwareModule`` (``ik``, ``ik_trace``), ``TickRunner``
- :mod:`.sil`       ``CFixedPointLaw``: the fixed-point law with its tick by compiled C (``drake.systems`` runs it)
- :mod:`.check`     ``check_ik``, ``check_tick``: a user's C vs the emulation (sd_ik over poses, sd_tick over a
                    recorded stream; ``drake.firmware_check.check_firmware`` records it from a closed loop)
- :mod:`.engine`    ``resolve_engine``: ``c`` if a compiler exists, else ``python`` with a note;
                    ``default_engine``: a closed loop's (``c`` for the fixed-point controller)
"""
