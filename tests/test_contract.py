"""The paper contract as a command (issue 30): it passes on every paper and names each planted violation."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from netrepro.judging.contract import check_paper
from netrepro.pipeline.registry import paper_slugs

ROOT = Path(__file__).resolve().parents[1]
SLUG = "intermittent"


def parts(slug):
    """What check_paper reads of a checkout for paper ``slug``."""
    return ("src/netrepro/papers.yaml", f"src/netrepro/papers/{slug}",
            f"workflow/schemas/{slug}.schema.yaml", "workflow/schemas/config.schema.yaml",
            "workflow/schemas/steps.schema.yaml",
            f"workflow/notebooks/{slug}.ipynb", f"workflow/report/{slug}", f"tests/papers/{slug}",
            f"tests/reference/{slug}", "config/config.yaml", "config/test.yaml")


def copy_parts(slug, target: Path) -> Path:
    """A scratch checkout with the files of paper ``slug`` that the contract reads."""
    for part in parts(slug):
        src, dst = ROOT / part, target / part
        dst.parent.mkdir(parents=True, exist_ok=True)
        (shutil.copytree if src.is_dir() else shutil.copy2)(src, dst)
    return target


@pytest.mark.parametrize("slug", paper_slugs())
def test_every_registered_paper_follows_the_contract(slug):
    violations = check_paper(slug, ROOT)
    assert not violations, "\n".join(map(str, violations))


def test_the_command_passes_on_all_papers_and_exits_zero():
    proc = subprocess.run([sys.executable, "-m", "netrepro", "check-paper", "--root", str(ROOT)],
                          capture_output=True, text=True, check=False)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert all(f"check-paper {slug}: ok" in proc.stdout for slug in paper_slugs())


@pytest.fixture
def scratch(tmp_path):
    """The files of one paper that the contract reads, in a scratch checkout."""
    copy_parts(SLUG, tmp_path)
    assert not check_paper(SLUG, tmp_path)
    return tmp_path


def _append(path: Path, text: str) -> int:
    """Append ``text`` to ``path``; return the line number of its first line."""
    old = path.read_text()
    path.write_text(old.rstrip("\n") + "\n" + text)
    return len(old.rstrip("\n").splitlines()) + 1


def _named(violations, check, path, line=None):
    return [v for v in violations if v.check == check and v.path == path and (line is None or v.line == line)]


def test_each_planted_violation_is_named_with_file_and_line(scratch):
    pkg = f"src/netrepro/papers/{SLUG}"
    (scratch / pkg / "checks.py").unlink()
    fig_line = _append(scratch / pkg / "figures.py", "from .model import lambda_c\n")
    io_line = _append(scratch / pkg / "model.py", "import pandas as pd\n")
    api_line = _append(scratch / pkg / "exact.py", "def forgotten(x):\n    return x\n")
    two = scratch / pkg / "two_sensor.py"
    doc_line = _append(two, "def undocumented(x):\n    \"\"\"No sections.\"\"\"\n    return x\n")
    two.write_text(two.read_text().replace("__all__ = [", "__all__ = [\"undocumented\", ", 1))
    claims = scratch / pkg / "claims.yaml"
    text = claims.read_text()
    first_quantity = text.split("quantity: ", 1)[1].split("}", 1)[0].split("\n", 1)[0].strip()
    claims.write_text(text.replace(f"quantity: {first_quantity}", "quantity: no_such_quantity", 1))
    spec_line = _append(scratch / pkg / "figures.yaml", "figS9:\n  plot: figure_nowhere\n")
    steps = scratch / pkg / "steps.yaml"
    step_text = steps.read_text()
    steps.write_text(step_text.replace("config: {from: two_sensor, keys: [a, n_dense]}",
                                       "config: {from: two_sensor, keys: [a, n_dense, no_such_step_key]}")
                     .replace("func: steps:heavy_tail_step", "func: steps:no_such_step")
                     + "  whole_step:\n    func: steps:exact_mean_step\n"
                       "    outputs: {table: results/intermittent/whole.csv}\n    config: {}\n")
    closed_line = step_text[:step_text.index("\n  region_closed_form:")].count("\n") + 2
    whole_step_line = len(step_text.splitlines()) + 1
    # a hand-written rules file beside the generated rules (optional) is held to the same checks
    smk = scratch / f"workflow/rules/{SLUG}.smk"
    smk.parent.mkdir(parents=True, exist_ok=True)
    smk.write_text('ICFG = config.get("intermittent", {})\n')
    rule_line = _append(smk, "\n\nrule wrong_prefix:\n    output:\n        'x'\n    shell:\n        'touch {output}'\n")
    key_line = _append(smk, "\nEXTRA = pick(ICFG.get('scalar', {}), 'a', 'no_such_key')\n")
    whole_line = _append(smk, "\n\nrule intermittent_whole:\n    params:\n        cfg=as_json(ICFG),\n")

    found = check_paper(SLUG, scratch)
    text = "\n".join(map(str, found))
    assert _named(found, "roles", f"{pkg}/checks.py"), text
    assert _named(found, "figures-imports", f"{pkg}/figures.py", fig_line), text
    assert _named(found, "math-io", f"{pkg}/model.py", io_line), text
    assert _named(found, "public-api", f"{pkg}/exact.py", api_line), text
    assert [v for v in _named(found, "public-api", f"{pkg}/two_sensor.py", doc_line) if "Parameters" in v.message], text
    assert [v for v in _named(found, "claim-quantity", f"{pkg}/claims.yaml") if "no_such_quantity" in v.message], text
    assert [v for v in _named(found, "figure-spec", f"{pkg}/figures.yaml", spec_line) if "figure_nowhere" in v.message]
    assert [v for v in _named(found, "figure-spec", f"{pkg}/figures.yaml", spec_line) if "caption" in v.message]
    assert [v for v in _named(found, "rule-name", f"workflow/rules/{SLUG}.smk") if "wrong_prefix" in v.message], text
    assert _named(found, "rule-name", f"workflow/rules/{SLUG}.smk", rule_line + 2), text
    assert [v for v in _named(found, "config-key", f"workflow/rules/{SLUG}.smk", key_line + 1)
            if "intermittent.scalar.no_such_key" in v.message], text
    assert [v for v in _named(found, "whole-section", f"workflow/rules/{SLUG}.smk", whole_line + 4)
            if "ICFG" in v.message], text
    # the step list: a function its module lacks, a key the schema lacks, a step reading the whole section
    assert [v for v in _named(found, "steps", f"{pkg}/steps.yaml") if "no_such_step" in v.message], text
    assert [v for v in _named(found, "config-key", f"{pkg}/steps.yaml", closed_line)
            if "intermittent.two_sensor.no_such_step_key" in v.message], text
    assert [v for v in _named(found, "whole-section", f"{pkg}/steps.yaml", whole_step_line)
            if "whole_step" in v.message], text
    # and nothing else: every violation is one of those planted
    assert len(found) == 15, text


def test_a_missing_reference_folder_is_a_violation(scratch):
    shutil.rmtree(scratch / f"tests/reference/{SLUG}")
    found = check_paper(SLUG, scratch)
    assert [v for v in found if v.check == "roles" and v.path == f"tests/reference/{SLUG}"], found


def test_a_citation_whose_authors_are_not_the_papers_is_a_violation(scratch):
    # what tests/test_release_files.py checks, said by check-paper (a new paper's citation left as TODO
    # while its authors line was filled in passed check-paper and failed the tests)
    registry = scratch / "src/netrepro/papers.yaml"
    text = registry.read_text()
    start = text.index(f"\n{SLUG}:")
    end = text.index("\ngainsched:")
    section = text[start:end]
    family = re.search(r"family-names: ([^\n,}]+)", section).group(1).strip()
    registry.write_text(text[:start] + section.replace(f"family-names: {family}", "family-names: Nobody", 1) + text[end:])
    found = check_paper(SLUG, scratch)
    assert [v for v in found if v.check == "citation" and "Nobody" in v.message and v.line > 0], found
    registry.write_text(text)
    assert not [v for v in check_paper(SLUG, scratch) if v.check == "citation"]


def test_an_unregistered_paper_is_a_violation(scratch):
    registry = scratch / "src/netrepro/papers.yaml"
    text = registry.read_text()
    start = text.index(f"\n{SLUG}:")
    end = text.index("\ngainsched:")
    registry.write_text(text[:start] + text[end:])
    found = check_paper(SLUG, scratch)
    assert [v for v in found if v.check == "roles" and "not registered" in v.message], found


# ----------------------------------------------------------------------------- issue 39: params carry picked keys
WHOLE_SECTION_SMK = '''
HCFG = config.get("hinf", {})


rule hinf_whole:
    params:
        cfg=as_json(HCFG),
        rule="hinf_whole",


rule hinf_nested:
    params:
        cfg=lambda w: as_json({"scenario": w.scenario, "cfg": HCFG}),


rule hinf_config:
    params:
        cfg=as_json(config["hinf"]),
        other=as_json(config),


rule hinf_picked:
    params:
        # passing HCFG whole here would rerun the step on any edit
        cfg=as_json(pick(HCFG, "noise", "noise_check")),
        sub=as_json({**pick(HCFG, "claims"), "scenarios": pick(HCFG.get("scenarios", {}), "fig2")}),
        entry=as_json(HCFG["network"]),
        shards=as_json(config["shards"]),
'''


@pytest.fixture(scope="module")
def hinf_checkout(tmp_path_factory):
    return copy_parts("hinf", tmp_path_factory.mktemp("hinf"))


def _whole_section(smk_text: str, checkout: Path):
    """check_paper's whole-section violations with ``smk_text`` as a hand-written workflow/rules/hinf.smk."""
    smk = checkout / "workflow/rules/hinf.smk"
    smk.parent.mkdir(parents=True, exist_ok=True)
    smk.write_text(smk_text)
    try:
        return [v for v in check_paper("hinf", checkout) if v.check == "whole-section"]
    finally:
        smk.unlink()


def _hand_written_hinf_rules() -> str:
    """workflow/rules/hinf.smk as written by hand before the step lists (issue 39), from the history."""
    before = subprocess.run(["git", "show", "09c12ef:workflow/rules/hinf.smk"], cwd=ROOT, capture_output=True,
                            text=True, check=False)
    if before.returncode != 0:
        pytest.skip("the history before the step lists is not at hand (a shallow clone)")
    return before.stdout


def test_params_passing_a_whole_section_are_named_with_file_and_line(hinf_checkout):
    found = _whole_section(WHOLE_SECTION_SMK, hinf_checkout)
    lines = WHOLE_SECTION_SMK.splitlines()
    where = {(v.path, v.line) for v in found}
    expected = {("workflow/rules/hinf.smk", i + 1) for i, text in enumerate(lines)
                if text.strip().startswith(("cfg=as_json(HCFG)", "cfg=lambda w:", "cfg=as_json(config[", "other="))}
    assert where == expected and len(found) == 4, "\n".join(map(str, found))
    assert any('config["hinf"]' in v.message for v in found)


def _unpicked(text: str) -> str:
    """The hinf rules as they were before issue 39: every ``pick(HCFG, ...)`` replaced by ``HCFG``."""
    from netrepro.judging.contract import _calls
    calls = [(offset, source) for offset, source in _calls(text, "pick") if re.match(r"pick\(\s*HCFG\s*,", source)]
    for offset, source in reversed(calls):
        text = text[:offset] + "HCFG" + text[offset + len(source):]
    return text


def test_the_old_hinf_rules_fail_the_check_and_the_new_pass(hinf_checkout):
    new = _hand_written_hinf_rules()
    assert not _whole_section(new, hinf_checkout)
    # every hinf rule but hinf_tables passed the whole section: as_json(HCFG), {"cfg": HCFG, ...}
    old = _unpicked(new)
    found = _whole_section(old, hinf_checkout)
    assert len(found) == 20, "\n".join(map(str, found))
    assert len({v.line for v in found}) == 20
    assert all("HCFG" in old.splitlines()[v.line - 1] for v in found)
    # and the text of the last commit before the change, where the history is at hand
    before = subprocess.run(["git", "show", "94f38aa:workflow/rules/hinf.smk"], cwd=ROOT, capture_output=True,
                            text=True, check=False)
    if before.returncode == 0:
        found = _whole_section(before.stdout, hinf_checkout)
        assert len(found) == 20, "\n".join(map(str, found))
        assert all("HCFG" in before.stdout.splitlines()[v.line - 1] for v in found)


@pytest.mark.parametrize("slug", paper_slugs())
def test_no_paper_passes_its_whole_section(slug):
    assert not [v for v in check_paper(slug, ROOT) if v.check == "whole-section"]


# ----------------------------------------------------------------------------- configuration keys named in the data files
def test_a_configuration_key_the_data_files_name_must_exist(scratch):
    """``(config <key>`` in a data file's text names a key of the paper's configuration section (issue 40 item 2)."""
    recon = scratch / f"src/netrepro/papers/{SLUG}/reconstructions.yaml"
    line = _append(recon, '- key: scalar.planted_choice\n'
                          '  reason: "a choice of ours"\n'
                          '  range: "0.1 and 0.2 (config evidence.no_such_key); horizon (config scalar.horizon), '
                          'rtol (config growth_ratio_rtol), runs (config no_such_leaf), a (config intermittent.scalar.a)"\n')
    found = _named(check_paper(SLUG, scratch), "config-reference", f"src/netrepro/papers/{SLUG}/reconstructions.yaml")
    assert {v.line for v in found} == {line + 2}
    messages = " ".join(v.message for v in found)
    # the missing keys are named, with the entry, the configurations and the fix
    assert "'evidence.no_such_key'" in messages and "'no_such_leaf'" in messages and "scalar.planted_choice" in messages
    assert "config/config.yaml and config/test.yaml" in messages and "add the key" in messages
    # existing keys are not: a dotted path from the section, and a bare key at any depth of it
    assert "scalar.horizon" not in messages and "growth_ratio_rtol" not in messages and "scalar.a'" not in messages
    assert len(found) == 2


def test_a_key_missing_from_one_configuration_names_that_one(scratch):
    claims = scratch / f"src/netrepro/papers/{SLUG}/claims.yaml"
    text = claims.read_text()
    assert "(config growth_ratio_rtol)" in text
    test_yaml = scratch / "config/test.yaml"
    test_yaml.write_text(test_yaml.read_text().replace("growth_ratio_rtol:", "growth_ratio_rtol_renamed:"))
    found = _named(check_paper(SLUG, scratch), "config-reference", f"src/netrepro/papers/{SLUG}/claims.yaml")
    assert len(found) == 1 and "config/test.yaml" in found[0].message and "config/config.yaml" not in found[0].message
    assert found[0].line == text[:text.index("(config growth_ratio_rtol)")].count("\n") + 1


def test_reconstruction_keys_and_settings_are_not_configuration_paths(scratch):
    """A reconstruction's key names a choice (``steady_state``), not a configuration key: not checked."""
    recon = scratch / f"src/netrepro/papers/{SLUG}/reconstructions.yaml"
    _append(recon, '- key: scalar.not_a_config_key\n  reason: "a modelling choice named by its key"\n')
    assert not _named(check_paper(SLUG, scratch), "config-reference", f"src/netrepro/papers/{SLUG}/reconstructions.yaml")


def test_analysis_role_is_the_evidences(tmp_path):
    """``analysis.py`` (the evidence mathematics): evidence.py imports it, a step module may not."""
    from netrepro.judging.contract import ANALYSIS, _check_analysis_role

    pkg = tmp_path / "src/netrepro/papers/demo"
    pkg.mkdir(parents=True)
    (pkg / ANALYSIS).write_text('"""Evidence mathematics."""\n')
    (pkg / "evidence.py").write_text("from .analysis import residual\n")
    (pkg / "steps.py").write_text("import numpy as np\n")
    assert _check_analysis_role(pkg, tmp_path) == []
    (pkg / "steps.py").write_text("import numpy as np\n\nfrom .analysis import residual\n")
    (pkg / "evidence.py").write_text("from .model import f\n")
    found = {(v.path, v.line, v.check) for v in _check_analysis_role(pkg, tmp_path)}
    assert found == {("src/netrepro/papers/demo/analysis.py", 0, "analysis-role"),
                     ("src/netrepro/papers/demo/steps.py", 3, "analysis-role")}
