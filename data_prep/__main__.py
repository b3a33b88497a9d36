"""data_prep: converters from real datasets to dataset folders. Run `python -m data_prep.bvh --help`."""
print(__doc__)
