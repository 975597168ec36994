"""The model-agnostic JCGM 101 + GUM engine (knows no lidar)."""
