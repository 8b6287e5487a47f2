"""Hidden-effect data: the settings of a model's runs with one mechanism
switched on, for tests and power studies of the workflow."""


def hidden_settings(model, condition, levels, hidden_set, name, value, fixed=None):
    """One settings dict per level of the condition: the model's own settings,
    then `fixed`, the mechanism's settings `hidden_set` and its parameter
    `name` = value. `condition` is one condition name (levels are numbers) or
    a tuple of names (levels are tuples of numbers, one per name)."""
    names = (condition,) if isinstance(condition, str) else tuple(condition)
    out = []
    for level in levels:
        s = dict(model.set)
        s.update(fixed or {})
        s.update(hidden_set)
        s[name] = value
        for cname, lv in zip(names, (level,) if isinstance(condition, str) else level):
            s[model.conditions[cname]] = float(lv)
        out.append(s)
    return out


def catalogue_subset(src, names, dst, choices=None):
    """Write to dst the candidates of the catalogue src whose names are in
    `names`; a parameter named in `choices` is tried at those values only
    (instead of its range)."""
    import json
    with open(src) as f:
        cat = json.load(f)
    cat["candidates"] = [k for k in cat["candidates"] if k["name"] in names]
    for k in cat["candidates"]:
        for prm in k.get("params", []):
            if prm["name"] in (choices or {}):
                for key in ("lower", "upper", "scale", "initial"):
                    prm.pop(key, None)
                prm["choices"] = choices[prm["name"]]
    with open(dst, "w") as f:
        json.dump(cat, f)
    return dst
