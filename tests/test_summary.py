"""Scorecard and replication summaries (netrepro.judging.summary): counted from tables, never typed."""

import pandas as pd

from netrepro.judging.summary import replication_summary, scorecard, summary_sentences


def claims(*rows):
    return pd.DataFrame(rows, columns=["claim_id", "verdict", "group", "location", "condition", "erratum_id", "note"])


A = claims(
    ("C1", "reproduced", "Fig 1", "figure 1", "", "", ""),
    ("C2", "conditional", "Fig 1", "section 3, figure 1", "holds for k <= 50; not for k = 200", "", ""),
    ("C3", "differs", "Theorem 2", "section 4", "", "", "ours 0.61. The paper rounds."),
    ("C4", "not_identifiable", "Theorem 2", "section 4", "", "", ""),
    ("C5", "erratum", "Remark 1", "remark 1", "", "E2", ""),
    ("C6", "context", "Remark 1", "remark 1", "", "", ""),
    ("C7", "reproduced", "Fig. 3 text", "figure 3", "", "", ""),
)


def test_scorecard_counts_every_category_and_scores_only_testable_ones():
    errata = {"a": pd.DataFrame({"kind": ["equation", "notation", "prose", "typesetting"]})}
    findings = {"a": pd.DataFrame({"finding_id": ["F1", "F2"]})}
    other = pd.DataFrame({"verdict": ["reproduced", "pending"]})
    score = scorecard({"a": A, "b": other}, errata, findings).set_index("paper")
    a = score.loc["a"]
    assert (a["claims"], a["testable"], a["reproduced"], a["conditional"], a["differs"], a["erratum"]) == (7, 5, 2, 1, 1, 1)
    assert (a["not_identifiable"], a["context"], a["not_checkable"], a["other"]) == (1, 1, 0, 0)
    assert a["scored_reproduced_pct"] == 40.0  # 2 of 5 testable, untestable rows not in the denominator
    assert (a["errata"], a["minor_errata"], a["findings"]) == (2, 2, 2)  # notation/typesetting do not count
    assert score.loc["b", "other"] == 1 and score.loc["b", "findings"] == 0
    assert score.loc["total", "claims"] == 9 and score.loc["total", "testable"] == 6


def test_replication_summary_per_figure_and_group():
    table = replication_summary(A, ["fig1", "fig2", "fig3", "figS1"]).set_index("item")
    assert table.loc["Fig 1", "status"] == "partially" and "C2 conditional (holds for k <= 50" in table.loc["Fig 1", "why"]
    assert table.loc["Fig 2", "status"] == "no claim"           # nothing stated on it
    assert table.loc["Fig 3", "status"] == "replicated"         # found through its location
    assert "Fig S1" not in table.index                          # our figures are not the paper's
    assert table.loc["Theorem 2", "status"] == "not replicated" and "C3 differs (ours 0.61." in table.loc["Theorem 2", "why"]
    assert table.loc["Remark 1", "status"] == "not replicated" and "erratum E2" in table.loc["Remark 1", "why"]
    only_context = replication_summary(claims(("X", "context", "Intro", "section 1", "", "", "")), [])
    assert only_context.iloc[0]["status"] == "not testable"


def test_summary_sentences_carry_the_counted_numbers():
    errata = pd.DataFrame({"kind": ["equation", "notation"]})
    text = " ".join(summary_sentences(A, errata, pd.DataFrame({"finding_id": ["F1"]}),
                                      replication_summary(A, ["fig1", "fig2"])))
    assert "Of 5 testable claims, 2 are reproduced, 1 holds only under a condition" in text
    assert "1 differs and 1 is wrong" in text and "2 further rows are kept" in text
    assert "Of its 2 figures, 1 partially, 1 no claim" in text
    assert "1 errata of substance" in text and "1 notation or typesetting" in text and "1 findings" in text
