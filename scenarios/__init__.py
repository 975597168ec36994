"""The shipped scenarios, installed with the package as ``uq.shipped`` (see ``uq.pipeline.shipped``)."""
