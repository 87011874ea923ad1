"""The 4D camera: its frame, the slice, rays and the bounding ball."""
