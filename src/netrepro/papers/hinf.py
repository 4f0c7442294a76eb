"""Paper `hinf` (placeholder until the paper is added)."""
