# Rules of the `gainsched` paper (placeholder until the paper is added).
