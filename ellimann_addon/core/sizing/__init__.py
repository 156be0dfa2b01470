"""Measurement files people already have, read and written: Seamly2D / Valentina (.vit, .vst), FreeSewing sets
(.json) and size charts (.csv), their names mapped onto ElliMann's eleven by definition, a missing one of the five
predicted from survey statistics (floor 5: synthesis and below).

- formula: the tools' measurement formulas, parsed and evaluated safely (references, cycles, functions)
- names: each format's names, and which ElliMann measurement each is, by definition (the mapping tables)
- predict: a missing measurement as the survey's conditional mean given the others
- rows: a file's rows (SizeRow, MeasurementFile), units, each row's checks, the reference sets' ranges
- readers: read_vit, read_vst, read_freesewing, read_chart, read_measurement_file
- writers: a mannequin's measurements back as a .vit, a FreeSewing set or a chart row
- mapping_doc: docs/formats/measurement_files.md's mapping tables, generated from names
"""
