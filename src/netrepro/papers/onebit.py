"""Paper `onebit` (placeholder until the paper is added)."""
