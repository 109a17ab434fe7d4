"""meshmark package."""
