"""Structure from motion: features, matching, tracks, reconstruction and bundle adjustment."""
