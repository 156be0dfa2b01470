"""A stand-in for ``UILayout`` that records what a panel draws and checks names against Blender.

There is no GUI on the test machines, so panel ``draw`` functions are called with this recorder:
a misspelt property or operator id, or a crash inside ``draw``, fails the test.
"""

import bpy


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
        self.log.append(("prop", {"data": data, "prop": prop, **kwargs}))

    def prop_menu_enum(self, data, prop, **kwargs):
        self.prop(data, prop, **kwargs)

    def props_enum(self, data, prop):
        self.prop(data, prop)

    def operator(self, idname, **kwargs):
        module, _, name = idname.partition(".")
        if not hasattr(getattr(bpy.ops, module), name) or not _operator_exists(idname):
            raise AttributeError(f"no operator '{idname}'")
        self.log.append(("operator", {"idname": idname, **kwargs}))
        return _OperatorProps()

    def menu(self, menu, **kwargs):
        if not hasattr(bpy.types, menu):
            raise AttributeError(f"no menu '{menu}'")
        self.log.append(("menu", {"menu": menu, **kwargs}))

    def label(self, **kwargs):
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
    """Accepts property assignments on an operator button (``op = layout.operator(...); op.x = 1``)."""


def _operator_exists(idname):
    module, _, name = idname.partition(".")
    try:
        getattr(getattr(bpy.ops, module), name).get_rna_type()
    except (KeyError, AttributeError):
        return False
    return True


class _Instance:
    """Stands in for an instance of a registered Panel or Menu class (bpy cannot make one outside a UI):
    class attributes and methods (``draw``, ``path_menu``...) resolve on the class, bound to this object."""

    def __init__(self, cls):
        self._cls = cls

    def __getattr__(self, name):
        value = getattr(self._cls, name)
        binder = getattr(value, "__get__", None)
        if callable(value) and binder is not None and not isinstance(value, type):
            plain = self._cls.__dict__.get(name) if name in self._cls.__dict__ else None
            if isinstance(plain, (classmethod, staticmethod)):
                return value
            function = getattr(value, "__func__", value)
            return function.__get__(self, type(self))
        return value


def draw_panel(panel_class, context=None):
    """Run a panel class's ``draw`` (and ``draw_header`` if any) against a Recorder; return it."""
    context = context or bpy.context
    panel = _Instance(panel_class)
    recorder = Recorder()
    panel.layout = recorder
    if hasattr(panel_class, "poll") and not panel_class.poll(context):
        return recorder
    if hasattr(panel_class, "draw_header"):
        panel.draw_header(context)
    panel.draw(context)
    return recorder
