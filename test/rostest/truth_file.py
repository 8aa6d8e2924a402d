"""The simulator's ground-truth sidecar (BAG.truth.csv), as the rostests
read it. The format is steadiface_core/sim/truth_file.h's (written by
steadiface_simulate, read by steadiface_bag): a settings line
"# steadiface truth v1 key=value ...", the column names, one row per frame.
"""
import csv

MAGIC = "# steadiface truth v1"


def read_truth(path):
    """(settings, rows): the settings line as a dict of strings ({} when the
    file has none) and the rows as dicts of column -> string."""
    settings = {}
    with open(path) as f:
        lines = []
        for line in f:
            if line.startswith(MAGIC):
                for word in line[len(MAGIC):].split():
                    k, _, v = word.partition("=")
                    settings[k] = v.replace("%20", " ")
            elif not line.startswith("#"):
                lines.append(line)
    return settings, list(csv.DictReader(lines))
