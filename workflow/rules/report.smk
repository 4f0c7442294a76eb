# The combined report: report/index.html from every paper's claims, errata, figures and sidecars.
import platform

from netrepro.provenance import params_hash



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
    conda:
        CONDA_ENV
    log:
        "logs/report.log",
    shell:
        step("netrepro.reportgen:build_index")
