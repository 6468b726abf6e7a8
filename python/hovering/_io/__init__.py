"""Files and trust (private): saving and loading results and maps (:mod:`.serial`), the limits on
files from elsewhere (:mod:`.untrusted`), atomic outputs and output folders (:mod:`.output`), what
made a result (:mod:`.provenance`), xarray/pandas views (:mod:`.interop`) and the one record of a
map's parameters that pickles, NPZ files and checkpoint keys share (:mod:`.records`)."""
