"""Claims, errata and reconstructions of `markov` on the tiny configuration."""

from __future__ import annotations

import pandas as pd

from netrepro.claims import CLAIM_COLUMNS, ERRATA_COLUMNS, RECONSTRUCTION_COLUMNS


def test_claims_errata_reconstructions(markov_tables):
    t = markov_tables
    claims = pd.read_csv(t["claims"])
    assert list(claims.columns) == CLAIM_COLUMNS
    row = claims.set_index("claim_id").loc["exII_thm5_q05"]
    assert abs(float(row.reproduced_value) - 0.4645062) < 1e-5
    assert claims.set_index("claim_id").loc["exII_p0465_certified", "verdict"] == "erratum"
    assert list(pd.read_csv(t["errata"]).columns) == ERRATA_COLUMNS
    assert list(pd.read_csv(t["recon"]).columns) == RECONSTRUCTION_COLUMNS
