"""Picking and selection on an Embree index: numpy arrays in, face ids out."""
