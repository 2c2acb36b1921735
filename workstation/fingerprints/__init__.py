"""WiFi fingerprints (§V-C): radio maps, the 1-NN index, device offsets, points on standby, localization and map quality."""
