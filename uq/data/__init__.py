"""Data shipped with uq (see README.md here for sources and licences)."""
from importlib import resources

#: Heights of the brightwind demo mast's north-boom anemometers [m] -> column.
BRIGHTWIND_SPEED_COLUMNS = {80.0: "Spd80mN", 60.0: "Spd60mN", 40.0: "Spd40mN"}


def brightwind_mast():
    """One year of 10-min records of the brightwind demo met mast (MIT licence).

    Returns
    -------
    pandas.DataFrame
        Indexed by ``Timestamp``; speeds [m s-1], directions [deg], ``T2m`` [degC].
    """
    import pandas
    path = resources.files(__name__) / "brightwind_demo_data_subset.csv.gz"
    with resources.as_file(path) as file:
        return pandas.read_csv(file, parse_dates=["Timestamp"], index_col="Timestamp")
