# Rules of the `hinf` paper (placeholder until the paper is added).
