#!/usr/bin/env python3
"""Score a multi-sensor model on the survey (RMS about one mean of comp −
true_external_k on lines > 0) and the oracle per cabin sensor: the same
terms fitted on the survey against the true field (lags searched there),
with the aeromag Python package (`pip install ./python`).

    python3 tools/validate/sensors_against_oracle.py MODEL.json SURVEY.csv
"""
import sys, json, numpy as np, aeromag
model_path, survey_path = sys.argv[1], sys.argv[2]
sur = aeromag.read_flight(survey_path)
m = aeromag.load_model(model_path)
c = m.compensate(sur)
line = sur["line"]
def rms(comp, k):
    r = (comp - sur[f"true_external_{k}"])[line > 0]
    r = r[np.isfinite(r)]
    return float(np.sqrt(np.mean((r - r.mean()) ** 2)))
doc = json.load(open(model_path))
rows = []
for s in doc["sensors"]:
    k = int(s["name"].split("_")[1])
    res = rms(c[f"{s['name']}_comp"], k)
    oracle = None
    if k > 1:
        terms = s["model"]["terms"]
        extras = [e["channel"] + (":lag" if "lag_s" in e else "") for e in terms.get("extras", [])]
        groups = ",".join(g for g in terms["groups"] if g != "bias")
        o = aeromag.calibrate_sensors(sur, [s["mag"]], vector="flux_a", reference_sensor=f"true_external_{k}",
                                      extra=extras, extra_selection="all", magnitude=s["model"]["magnitude"],
                                      terms=groups, eddy_lag=terms.get("eddy_lags_s") or "none")
        oracle = rms(o.compensate(sur)[f"{s['name']}_comp"], k)
    rows.append((s["name"], res, oracle))
for n, r, o in rows:
    print(f"{n}: {r:.3f}" + (f"  oracle {o:.3f}  ratio {r/o:.2f}" if o else ""))
