"""One module per paper. ``PAPERS`` maps each slug to its source text and title."""

__all__ = ["PAPERS"]

PAPERS = {
    "intermittent": {
        "file": "000_afcb209f5b7aba6b.txt",
        "title": "Kalman Filtering with Measurement Losses",
        "authors": "S. Teerikoski (report, 2014), after Sinopoli et al. 2004 and Liu & Goldsmith 2004",
    },
    "gainsched": {
        "file": "001_71d332bfa62fdf02.txt",
        "title": "Probability-Dependent Gain-Scheduled Filtering for Stochastic Systems with Missing Measurements",
        "authors": "G. Wei, Z. Wang, B. Shen, M. Li",
    },
    "onebit": {
        "file": "002_4ca26869a4ed5341.txt",
        "title": "Asymptotic Performance Analysis for 1-Bit Bayesian Smoothing",
        "authors": "L. Zhang, M. Stein, J. A. Nossek",
    },
    "hinf": {
        "file": "003_5fa54182c091b62a.txt",
        "title": "Decentralized H-infinity Filtering in a Multi-Agent System",
        "authors": "T. R. Nelson, R. A. Freeman",
    },
    "markov": {
        "file": "004_b2c5b76ae3d93bdf.txt",
        "title": "Stability Conditions and Phase Transition for Kalman Filtering over Markovian Channels",
        "authors": "J. Wu, G. Shi, B. D. O. Anderson, K. H. Johansson",
    },
}
