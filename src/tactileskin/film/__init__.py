"""Pressure-film analysis (paper Sec. IV-B to IV-D, Eqs. 7-8): calibration presses ->
grayscale-to-pressure map; scanned film -> pressure image and profile; comparison with a
simulated profile. numpy/scipy/Pillow only; matplotlib is imported lazily by ``plots``.
"""

from tactileskin.film.calibration import (  # noqa: F401
    Calibration,
    calibrate_csv,
    fit_calibration,
    load_calibration,
    paper_eq8,
    read_calibration_csv,
)
from tactileskin.film.compare import Comparison, compare  # noqa: F401
from tactileskin.film.scan import (  # noqa: F401
    FilmProfile,
    analyze_scan,
    fold_profile,
    load_grayscale,
    profile_metrics,
    select_region,
)
