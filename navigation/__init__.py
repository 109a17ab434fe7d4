"""Cost layers and planners: arrays in, arrays out."""
