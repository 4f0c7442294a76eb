# The combined report: report/index.html from every paper's claims, errata, figures and sidecars.
import platform

from netrepro.provenance import params_hash


def report_inputs(wildcards):
    """Every registered output of every enabled paper, as named inputs."""
    named = {}
    for slug, spec in PAPER_OUTPUTS.items():
        named[f"{slug}_figures"] = spec["figures"]
        named[f"{slug}_claims"] = spec["claims"]
        named[f"{slug}_errata"] = spec["errata"]
        named[f"{slug}_reconstructions"] = spec["reconstructions"]
        named[f"{slug}_notebook"] = spec["notebook"]
    return named


rule report:
    input:
        unpack(report_inputs),
        code=src("reportgen.py", "provenance.py"),
    output:
        html="report/index.html",
    params:
        cfg=as_json(
            {
                "papers": PAPER_OUTPUTS,
                "config_hash": params_hash(config),
                "machine": f"{platform.system()} {platform.machine()}",
            }
        ),
        io=io_json,
    log:
        "logs/report.log",
    shell:
        step("netrepro.reportgen:build_index")
