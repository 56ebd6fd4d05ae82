"""aeromag quick start: the notebook workflow of a compensation study.

Simulate (or read) a calibration flight, fit the Tolles-Lawson model by
both methods, compensate a survey, compare with the truth the simulator
knows, and save the model file the CLI would write.

    python examples/quickstart.py [OUT_DIR]

With a real flight instead: ``aeromag.read_flight("Flt1002.h5",
lines="1002.02")`` for the calibration box, ``lines=[1002.14, ...]`` for
survey lines (MagNav/SGL names are recognised; ``mag="mag_3_uc"`` picks
another magnetometer).
"""

import os
import sys

import numpy as np

import aeromag

out = sys.argv[1] if len(sys.argv) > 1 else "."
os.makedirs(out, exist_ok=True)

cal = aeromag.simulate("calibration", seed=1)
survey = aeromag.simulate("survey", seed=2)
print(f"calibration flight: {len(cal)} rows; survey: {len(survey)} rows")

for method, options in [("ls", {}), ("kalman", {"no_tune": True})]:
    tl = aeromag.TollesLawson(method=method, **options).fit(cal)
    comp = tl.transform(survey)
    # The simulator's truth (never read by the estimators): the
    # interference-free reading is the measured one minus the true interference.
    error = comp - (survey["mag"] - survey["true_interf"])
    error -= np.nanmean(error)
    print(
        f"{method:6s}: {len(tl.terms_)} terms, fit residual {tl.fit_stats_['residual_rms_nt']:.4f} nT, "
        f"survey error {np.sqrt(np.nanmean(error ** 2)):.4f} nT RMS"
    )
    tl.save(os.path.join(out, f"model_{method}.json"))

model = aeromag.load_model(os.path.join(out, "model_ls.json"))
print("coefficients of", model, ":", dict(zip(model.terms[:3], np.round(model.coef[:3], 3))))
field = aeromag.igrf(survey["lat"][:1], survey["lon"][:1], survey["alt"][:1], "2025-01-01")
print(f"IGRF total field at the first survey point: {field['f'][0]:.1f} nT")
