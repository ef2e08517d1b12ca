"""The file formats of a record, one module each: ``read(path, strain_scale)`` and
``write(path, record, meta)`` (:mod:`workbench.lab.files` picks one by suffix)."""
