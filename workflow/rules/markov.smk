# Rules of the `markov` paper (placeholder until the paper is added).
