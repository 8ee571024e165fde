"""Contact laws usable by the impact driver."""
