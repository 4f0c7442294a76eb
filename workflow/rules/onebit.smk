# Rules of the `onebit` paper (placeholder until the paper is added).
