"""Golden-lidar verification: calibration and classification uncertainty per
reference-wind-speed bin (IEC 61400-12-1 and LUSR), the golden-lidar chain, the
floating-lidar KPIs, and the ``uq golden`` report (Coll-Vinent & Miquel, FLS200 as a
golden floating lidar)."""
