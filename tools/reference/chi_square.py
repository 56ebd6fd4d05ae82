"""Reference values for aeromag-estimation's chi-square distribution
(crates/estimation/src/stats/chi_square.rs, test `matches_scipy`)."""
from scipy.stats import chi2

for k, p in [(9, 1 - 0.01 / 9), (9, 0.999), (18, 1 - 0.01 / 9), (1, 0.95), (9, 0.95)]:
    print(k, repr(p), repr(chi2.ppf(p, k)))
