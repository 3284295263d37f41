"""Helpers shared by the test areas: signals, data paths, VN sentences and the VN oracle."""
