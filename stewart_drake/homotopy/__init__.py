"""Complete forward kinematics by parameter homotopy in Study coordinates, with a certificate per real
solution. numpy only. Modules: ``study`` (the polynomial system, architecture classes), ``start``
(start systems by monodromy, shipped in ``data/``), ``track`` (vectorised path tracker), ``solve``
(path classification, completeness), ``certify`` (Krawczyk/Kantorovich existence-uniqueness test)."""

from stewart_drake.homotopy.solve import CLASSES, CertifiedMode, HomotopyResult, solve, solve_batch
from stewart_drake.homotopy.study import architecture

__all__ = ["CLASSES", "CertifiedMode", "HomotopyResult", "architecture", "solve", "solve_batch"]
