"""Files and units: presets (the only YAML reader/writer), unit conversion, number parsing, drive logs."""
