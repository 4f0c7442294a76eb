"""Paper `gainsched` (placeholder until the paper is added)."""
