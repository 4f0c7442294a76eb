"""Paper `markov` (placeholder until the paper is added)."""
