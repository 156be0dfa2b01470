"""A stand-in for ``UILayout`` that records what a panel draws and checks names against Blender.

There is no GUI on the test machines, so panel ``draw`` functions are called with this recorder:
a misspelt property, operator id, menu or icon name, or a crash inside ``draw``, fails the test.
"""

import functools

import bpy


@functools.cache
def icon_names():
    """Every icon name Blender accepts for ``icon=`` (the items of UILayout.prop's icon enum)."""
    return frozenset(bpy.types.UILayout.bl_rna.functions["prop"].parameters["icon"].enum_items.keys())


def _check_icon(kwargs):
    icon = kwargs.get("icon")
    if icon is not None and icon not in icon_names():
        raise ValueError(f"'{icon}' is not a Blender icon name")


class Recorder:
    """Records ``prop``, ``operator``, ``label``... calls; nested layouts record into the same log."""

    def __init__(self, log=None):
        self.log = [] if log is None else log
        self.enabled = True
        self.active = True
        self.alert = False
        self.use_property_split = False
        self.use_property_decorate = False
        self.scale_y = 1.0
        self.scale_x = 1.0
        self.alignment = "EXPAND"
        self.operator_context = "INVOKE_DEFAULT"

    def _child(self, kind, **kwargs):
        self.log.append((kind, kwargs))
        return Recorder(self.log)

    def row(self, **kwargs):
        return self._child("row", **kwargs)

    def column(self, **kwargs):
        return self._child("column", **kwargs)

    def box(self, **kwargs):
        return self._child("box", **kwargs)

    def split(self, **kwargs):
        return self._child("split", **kwargs)

    def grid_flow(self, **kwargs):
        return self._child("grid_flow", **kwargs)

    def column_flow(self, **kwargs):
        return self._child("column_flow", **kwargs)

    def panel(self, idname, **kwargs):
        self.log.append(("panel", {"idname": idname, **kwargs}))
        return Recorder(self.log), Recorder(self.log)

    def prop(self, data, prop, **kwargs):
        if prop not in data.bl_rna.properties:
            raise AttributeError(f"{type(data).__name__} has no property '{prop}'")
        _check_icon(kwargs)
        self.log.append(("prop", {"data": data, "prop": prop, **kwargs}))

    def operator(self, idname, **kwargs):
        rna = _operator_rna(idname)
        if rna is None:
            raise AttributeError(f"no operator '{idname}'")
        _check_icon(kwargs)
        props = _OperatorProps(idname, rna)
        self.log.append(("operator", {"idname": idname, "props": props.values, **kwargs}))
        return props

    def operator_menu_enum(self, idname, prop, **kwargs):
        self.operator(idname)._check(prop)
        _check_icon(kwargs)
        self.log.append(("operator_menu_enum", {"idname": idname, "prop": prop, **kwargs}))

    def prop_search(self, data, prop, search_data, search_prop, **kwargs):
        if prop not in data.bl_rna.properties:
            raise AttributeError(f"{type(data).__name__} has no property '{prop}'")
        if search_prop not in search_data.bl_rna.properties:
            raise AttributeError(f"{type(search_data).__name__} has no collection '{search_prop}'")
        _check_icon(kwargs)
        self.log.append(("prop", {"data": data, "prop": prop, "search": search_prop, **kwargs}))

    def menu(self, menu, **kwargs):
        if not hasattr(bpy.types, menu):
            raise AttributeError(f"no menu '{menu}'")
        _check_icon(kwargs)
        self.log.append(("menu", {"menu": menu, **kwargs}))

    def label(self, **kwargs):
        _check_icon(kwargs)
        self.log.append(("label", kwargs))

    def separator(self, **kwargs):
        self.log.append(("separator", kwargs))

    def template_list(self, *args, **kwargs):
        self.log.append(("template_list", {"args": args, **kwargs}))

    # Queries used by tests.
    def props(self):
        return [kw["prop"] for kind, kw in self.log if kind == "prop"]

    def operators(self):
        return [kw["idname"] for kind, kw in self.log if kind == "operator"]

    def labels(self):
        return [kw.get("text", "") for kind, kw in self.log if kind == "label"]


class _OperatorProps:
    """Property assignments on an operator button (``op = layout.operator(...); op.x = 1``), checked
    against the operator's properties (an enum value against its items)."""

    def __init__(self, idname, rna):
        object.__setattr__(self, "idname", idname)
        object.__setattr__(self, "rna", rna)
        object.__setattr__(self, "values", {})

    def _check(self, name):
        if name not in self.rna.properties:
            raise AttributeError(f"operator '{self.idname}' has no property '{name}'")
        return self.rna.properties[name]

    def __setattr__(self, name, value):
        prop = self._check(name)
        if prop.type == "ENUM" and not prop.is_enum_flag and prop.enum_items:
            if value not in prop.enum_items.keys():
                raise ValueError(f"'{value}' is not an item of {self.idname}.{name}: {prop.enum_items.keys()}")
        self.values[name] = value


def _operator_rna(idname):
    module, _, name = idname.partition(".")
    try:
        return getattr(getattr(bpy.ops, module), name).get_rna_type()
    except (KeyError, AttributeError):
        return None


class _StandIn:
    """Plays ``self`` for a Panel, Menu or Operator class outside Blender's drawing code: registered
    bpy_struct classes cannot be instantiated from Python. Unknown attributes come from the class, with
    its functions bound to the stand-in."""

    def __init__(self, cls, layout, **values):
        self.__dict__.update(values, _cls=cls, layout=layout)

    def __getattr__(self, name):
        attr = getattr(self._cls, name)
        if callable(attr) and hasattr(attr, "__get__") and not hasattr(attr, "__self__"):
            return attr.__get__(self)
        return attr


def draw_menu_function(draw, context=None):
    """Run a draw function appended to a Blender menu (``draw(self, context)``) against a Recorder."""
    recorder = Recorder()
    draw(_StandIn(object, recorder), context or bpy.context)
    return recorder


def draw_panel(panel_class, context=None, recorder=None):
    """Run a panel's (or menu's) ``draw`` (and ``draw_header`` if any) against a Recorder (or ``recorder``);
    return it.

    A panel whose ``poll`` fails is not drawn (the recorder stays empty), as in Blender.
    """
    context = context or bpy.context
    recorder = Recorder() if recorder is None else recorder
    panel = _StandIn(panel_class, recorder)
    if hasattr(panel_class, "poll") and not panel_class.poll(context):
        return recorder
    if hasattr(panel_class, "draw_header"):
        panel.draw_header(context)
    panel.draw(context)
    return recorder


def draw_operator(operator_class, context=None, **values):
    """Run an operator's own ``draw`` (its dialog / redo panel) against a Recorder, with property values."""
    module, _, name = operator_class.bl_idname.partition(".")
    rna = getattr(getattr(bpy.ops, module), name).get_rna_type()
    recorder = Recorder()
    operator_class.draw(_StandIn(operator_class, recorder, bl_rna=rna, **values), context or bpy.context)
    return recorder
