<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="de">
    <context>
        <name>TruOrtho</name>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Orientation</source>
            <translation>Orientierung</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Orthophoto</source>
            <translation>Orthophoto</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Surface</source>
            <translation>Oberfläche</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Tools</source>
            <translation>Werkzeuge</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="158" />
            <source>Restore the colour edges of JPEGs with half-resolution colour</source>
            <translation>Farbkanten von JPEGs mit halbierter Farbauflösung wiederherstellen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="170" />
            <source>Colour edges from the surface's height steps</source>
            <translation>Farbkanten aus den Höhensprüngen der Oberfläche</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="196" />
            <source>Run tiles on</source>
            <translation>Kacheln ausführen auf</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="209" />
            <source>Dask scheduler address (tls://host:port or scheduler file; empty = TRUORTHO_DASK_SCHEDULER)</source>
            <translation>Adresse des Dask-Schedulers (tls://host:port oder Scheduler-Datei; leer = TRUORTHO_DASK_SCHEDULER)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="229" />
            <source>Ground control points</source>
            <translation>Passpunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="235" />
            <source>GCP image measurements (table)</source>
            <translation>Bildmessungen der Passpunkte (Tabelle)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="120" />
            <source>TruOrtho algorithms could not be loaded: {}</source>
            <translation>TruOrtho-Algorithmen konnten nicht geladen werden: {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="172" />
            <source>off</source>
            <translation>aus</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="173" />
            <source>checked: where the photos agree with the surface</source>
            <translation>geprüft: wo die Fotos mit der Oberfläche übereinstimmen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="174" />
            <source>surface: at every height step (exact surfaces: LiDAR, building models)</source>
            <translation>Oberfläche: an jedem Höhensprung (exakte Oberflächen: LiDAR, Gebäudemodelle)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="198" />
            <source>inprocess: this process (all cores)</source>
            <translation>inprocess: dieser Prozess (alle Kerne)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="199" />
            <source>local: a Dask cluster of worker processes on this computer</source>
            <translation>local: ein Dask-Cluster aus Worker-Prozessen auf diesem Rechner</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="200" />
            <source>scheduler: a Dask scheduler (SCHEDULER_ADDRESS)</source>
            <translation>scheduler: ein Dask-Scheduler (SCHEDULER_ADDRESS)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="42" />
            <source>Detect ground targets</source>
            <translation>Bodenmarken erkennen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="73" />
            <source>Image folder</source>
            <translation>Bildordner</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="79" />
            <source>Target type</source>
            <translation>Markentyp</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="87" />
            <source>ArUco dictionary</source>
            <translation>ArUco-Wörterbuch</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="94" />
            <source>Marker IDs -&gt; GCP names (e.g. 0=GCP1,1=GCP2)</source>
            <translation>Marker-IDs -&gt; Passpunktnamen (z. B. 0=GCP1,1=GCP2)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="99" />
            <source>Orientation (TruOrtho JSON)</source>
            <translation>Orientierung (TruOrtho-JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="110" />
            <source>Search radius around predicted positions (px)</source>
            <translation>Suchradius um die vorhergesagten Positionen (px)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="119" />
            <source>Minimum score (lower scores are flagged)</source>
            <translation>Mindestbewertung (niedrigere Bewertungen werden markiert)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="128" />
            <source>Refine by least-squares matching</source>
            <translation>Mit Kleinste-Quadrate-Zuordnung verfeinern</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="134" />
            <source>Target measurements (observation table)</source>
            <translation>Markenmessungen (Beobachtungstabelle)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="197" />
            <source>MARKER_IDS: give the mapping of marker IDs to GCP names, e.g. 0=GCP1,1=GCP2</source>
            <translation>MARKER_IDS: geben Sie die Zuordnung von Marker-IDs zu Passpunktnamen an, z. B. 0=GCP1,1=GCP2</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="212" />
            <source>{} measurements ({} flagged) in {} images</source>
            <translation>{} Messungen ({} markiert) in {} Bildern</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>ArUco markers</source>
            <translation>ArUco-Marker</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>Circular targets</source>
            <translation>Kreisförmige Marken</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>Checkerboard (X) targets</source>
            <translation>Schachbrettmarken (X)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="194" />
            <source>{} predicted positions</source>
            <translation>{} vorhergesagte Positionen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="149" />
            <source>MARKER_IDS: GCP name(s) {} are not in the GCP layer (it has {})</source>
            <translation>MARKER_IDS: Passpunktname(n) {} fehlen im Passpunktlayer (er enthält {})</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="182" />
            <source>{} targets are searched near their predicted positions: give ORIENTATION and GCPS</source>
            <translation>{}-Marken werden nahe ihren vorhergesagten Positionen gesucht: geben Sie ORIENTATION und GCPS an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="190" />
            <source>No GCP projects into an image of {} with this orientation (the same photos?)</source>
            <translation>Kein Passpunkt wird mit dieser Orientierung in ein Bild von {} projiziert (dieselben Fotos?)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="32" />
            <source>Filter DSM (outliers, holes, smoothing, DTM)</source>
            <translation>DOM filtern (Ausreißer, Lücken, Glättung, DGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="320" />
            <source>Filtered DSM</source>
            <translation>Gefiltertes DOM</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="81" />
            <source>Raw DSM</source>
            <translation>Rohes DOM</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="83" />
            <source>Confidence raster [0, 1]</source>
            <translation>Konfidenzraster [0, 1]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="88" />
            <source>Outlier threshold (m; empty = 4 x resolution)</source>
            <translation>Ausreißerschwelle (m; leer = 4 x Auflösung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="98" />
            <source>Largest hole width filled (m)</source>
            <translation>Größte gefüllte Lückenbreite (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="106" />
            <source>Sharpen blurred height steps</source>
            <translation>Verschliffene Höhensprünge schärfen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="111" />
            <source>Edge-preserving smoothing of planar surfaces</source>
            <translation>Kantenerhaltende Glättung ebener Flächen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="117" />
            <source>Outlier window (cells, odd)</source>
            <translation>Ausreißerfenster (Zellen, ungerade)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="128" />
            <source>Supporting neighbours that keep a cell</source>
            <translation>Stützende Nachbarn, die eine Zelle erhalten</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="138" />
            <source>Minimum confidence</source>
            <translation>Mindestkonfidenz</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="149" />
            <source>Confident cells (confidence at least)</source>
            <translation>Zuverlässige Zellen (Konfidenz mindestens)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="160" />
            <source>Height step between surfaces (m)</source>
            <translation>Höhensprung zwischen Oberflächen (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="170" />
            <source>Smoothing radius (cells)</source>
            <translation>Glättungsradius (Zellen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="181" />
            <source>Smoothing height tolerance (m; empty = 2.5 x resolution)</source>
            <translation>Höhentoleranz der Glättung (m; leer = 2,5 x Auflösung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="192" />
            <source>Ground filter cell size (m; empty = max(1 m, resolution))</source>
            <translation>Zellgröße des Bodenfilters (m; leer = max(1 m, Auflösung))</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="203" />
            <source>Ground filter window radius (m)</source>
            <translation>Fensterradius des Bodenfilters (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="213" />
            <source>Ground filter slope (rise/run)</source>
            <translation>Neigung des Bodenfilters (Höhe/Strecke)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="224" />
            <source>Terrain model (DTM)</source>
            <translation>Geländemodell (DGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="229" />
            <source>Normalised DSM (height above terrain)</source>
            <translation>Normalisiertes DOM (Höhe über Gelände)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="232" />
            <source>Statistics (JSON)</source>
            <translation>Statistik (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="233" />
            <source>Outliers removed (cells)</source>
            <translation>Entfernte Ausreißer (Zellen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="234" />
            <source>Hole cells filled</source>
            <translation>Gefüllte Lückenzellen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="235" />
            <source>Holes left as nodata</source>
            <translation>Als NoData verbliebene Lücken</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="322" />
            <source>DTM</source>
            <translation>DGM</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="282" />
            <source>{} holes ({} cells, widest {:.1f} m) are wider than {} m and stay nodata</source>
            <translation>{} Lücken ({} Zellen, breiteste {:.1f} m) sind breiter als {} m und bleiben NoData</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="310" />
            <source>Ground filter at {:.2f} m: {:.1f} % of the cells are ground</source>
            <translation>Bodenfilter mit {:.2f} m: {:.1f} % der Zellen sind Boden</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="90" />
            <source>Check environment</source>
            <translation>Umgebung prüfen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="99" />
            <source>Reports the versions of QGIS, GDAL, rasterio, numpy, numba, OpenCV and pyproj that TruOrtho runs with, and writes them to a JSON file. Fails if rasterio is linked to a different GDAL than QGIS. Also reports TruOrtho's cache folder (compiled kernels and image features; the environment variable TRUORTHO_CACHE_DIR moves it, default the per-user cache folder of the system) and its size; CLEAR_CACHE empties it.</source>
            <translation>Meldet die Versionen von QGIS, GDAL, rasterio, numpy, numba, OpenCV und pyproj, mit denen TruOrtho läuft, und schreibt sie in eine JSON-Datei. Schlägt fehl, wenn rasterio gegen ein anderes GDAL als QGIS gelinkt ist. Meldet auch den Cache-Ordner von TruOrtho (kompilierte Kernel und Bildmerkmale; die Umgebungsvariable TRUORTHO_CACHE_DIR verlegt ihn, Vorgabe ist der benutzereigene Cache-Ordner des Systems) und seine Größe; CLEAR_CACHE leert ihn.</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="143" />
            <source>rasterio is linked to GDAL {} but QGIS uses GDAL {}: use Debian's python3-rasterio</source>
            <translation>rasterio ist gegen GDAL {} gelinkt, QGIS verwendet aber GDAL {}: verwenden Sie Debians python3-rasterio</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="113" />
            <source>Versions (JSON)</source>
            <translation>Versionen (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="113" />
            <source>JSON files (*.json)</source>
            <translation>JSON-Dateien (*.json)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="119" />
            <source>Clear the cache (compiled kernels, image features)</source>
            <translation>Cache leeren (kompilierte Kernel, Bildmerkmale)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="124" />
            <source>Versions as JSON text</source>
            <translation>Versionen als JSON-Text</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="131" />
            <source>Cache cleared: {:.1f} MB freed</source>
            <translation>Cache geleert: {:.1f} MB freigegeben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="140" />
            <source>Not importable: {}</source>
            <translation>Nicht importierbar: {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="136" />
            <source>not available</source>
            <translation>nicht verfügbar</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="21" />
            <source>Export orientation</source>
            <translation>Orientierung exportieren</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="36" />
            <source>Format</source>
            <translation>Format</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="41" />
            <source>Output folder</source>
            <translation>Ausgabeordner</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="42" />
            <source>Files written</source>
            <translation>Geschriebene Dateien</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="37" />
            <source>COLMAP text model</source>
            <translation>COLMAP-Textmodell</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="37" />
            <source>Orthority OPK CSV + interior file</source>
            <translation>Orthority-OPK-CSV + Datei der inneren Orientierung</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="54" />
            <source>Wrote {}</source>
            <translation>{} geschrieben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="26" />
            <source>Import GCP list</source>
            <translation>Passpunktliste importieren</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="44" />
            <source>GCP list (ODM gcp_list.txt)</source>
            <translation>Passpunktliste (ODM gcp_list.txt)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="47" />
            <source>Check point names (comma-separated)</source>
            <translation>Namen der Kontrollpunkte (kommagetrennt)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="53" />
            <source>Default sigma XY [m]</source>
            <translation>Standard-Sigma XY [m]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="62" />
            <source>Default sigma Z [m]</source>
            <translation>Standard-Sigma Z [m]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="68" />
            <source>Reproject to CRS</source>
            <translation>In KBS umprojizieren</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="76" />
            <source>GCP image measurements</source>
            <translation>Bildmessungen der Passpunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="129" />
            <source>{} GCPs ({} check points), {} image measurements</source>
            <translation>{} Passpunkte ({} Kontrollpunkte), {} Bildmessungen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="103" />
            <source>CHECK_POINTS: unknown GCP name(s) {}; the file has {}</source>
            <translation>CHECK_POINTS: unbekannte(r) Passpunktname(n) {}; die Datei enthält {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="44" />
            <source>Import orientation</source>
            <translation>Orientierung importieren</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="62" />
            <source>Orientation file (COLMAP, Orthority CSV, OpenSfM)</source>
            <translation>Orientierungsdatei (COLMAP, Orthority-CSV, OpenSfM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="66" />
            <source>Interior parameter file (Orthority)</source>
            <translation>Parameterdatei der inneren Orientierung (Orthority)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="71" />
            <source>CRS of the input (when the file has none)</source>
            <translation>KBS der Eingabe (wenn die Datei keins angibt)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="86" />
            <source>Footprint height</source>
            <translation>Höhe der Bildabdeckungen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="93" />
            <source>Orientation (JSON)</source>
            <translation>Orientierung (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="99" />
            <source>Cameras</source>
            <translation>Kameras</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="107" />
            <source>Footprints</source>
            <translation>Bildabdeckungen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="133" />
            <source>The orientation has no CRS: it stays in its arbitrary (local) frame. Give CRS (or a georef.json) to georeference it.</source>
            <translation>Die Orientierung hat kein KBS: sie bleibt in ihrem beliebigen (lokalen) System. Geben Sie CRS (oder eine georef.json) an, um sie zu georeferenzieren.</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="149" />
            <source>OBSERVATIONS given without a GCPS layer</source>
            <translation>OBSERVATIONS ohne GCPS-Layer angegeben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="123" />
            <source>Read {} images, {} cameras, {} sparse points</source>
            <translation>{} Bilder, {} Kameras, {} Punkte der dünnen Punktwolke gelesen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="153" />
            <source>GCPs need a georeferenced orientation: give CRS for the input</source>
            <translation>Passpunkte erfordern eine georeferenzierte Orientierung: geben Sie CRS für die Eingabe an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="130" />
            <source>{}: the orientation contains no images</source>
            <translation>{}: die Orientierung enthält keine Bilder</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="159" />
            <source>{} GCPs with {} image measurements</source>
            <translation>{} Passpunkte mit {} Bildmessungen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="194" />
            <source>Image {} does not see the plane at height {}</source>
            <translation>Bild {} sieht die Ebene in Höhe {} nicht</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="27" />
            <source>Mesh from DSM or point cloud</source>
            <translation>Vermaschung aus DOM oder Punktwolke</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="61" />
            <source>DSM raster or point cloud (LAS/LAZ, EPT ept.json)</source>
            <translation>DOM-Raster oder Punktwolke (LAS/LAZ, EPT ept.json)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="66" />
            <source>Orthoimage for vertex colours</source>
            <translation>Orthobild für die Eckpunktfarben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="71" />
            <source>Largest vertical error (m; empty = half the DSM resolution)</source>
            <translation>Größter Höhenfehler (m; leer = halbe DOM-Auflösung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="81" />
            <source>Smallest height step made a wall (m)</source>
            <translation>Kleinster Höhensprung, der zur Wand wird (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="90" />
            <source>Steepest slope kept as a surface (degrees)</source>
            <translation>Steilste als Fläche erhaltene Neigung (Grad)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="101" />
            <source>Largest flat block (cells, power of two)</source>
            <translation>Größter ebener Block (Zellen, Zweierpotenz)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="112" />
            <source>Point clouds: longest triangle edge (m; empty = automatic)</source>
            <translation>Punktwolken: längste Dreieckskante (m; leer = automatisch)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="123" />
            <source>Coordinates</source>
            <translation>Koordinaten</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="130" />
            <source>Mesh</source>
            <translation>Dreiecksnetz</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="130" />
            <source>PLY mesh (*.ply);;Wavefront OBJ (*.obj)</source>
            <translation>PLY-Netz (*.ply);;Wavefront OBJ (*.obj)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="133" />
            <source>Vertices</source>
            <translation>Eckpunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="134" />
            <source>Faces</source>
            <translation>Dreiecke</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="135" />
            <source>Wall faces</source>
            <translation>Wanddreiecke</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="62" />
            <source>DSM or point cloud (*.tif *.tiff *.las *.laz *.json);;All files (*.*)</source>
            <translation>DOM oder Punktwolke (*.tif *.tiff *.las *.laz *.json);;Alle Dateien (*.*)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="124" />
            <source>CRS (world coordinates)</source>
            <translation>KBS (Weltkoordinaten)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="124" />
            <source>Local frame (world - offset, offset in the header)</source>
            <translation>Lokales System (Welt - Offset, Offset im Dateikopf)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="155" />
            <source>ORTHO is ignored for point clouds (their own colours are used)</source>
            <translation>ORTHO wird bei Punktwolken ignoriert (ihre eigenen Farben werden verwendet)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="145" />
            <source>INPUT: file not found: {}</source>
            <translation>INPUT: Datei nicht gefunden: {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="158" />
            <source>{} points in {} reference systems</source>
            <translation>{} Punkte in {} Referenzsystemen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="176" />
            <source>{} cells -&gt; {} vertices ({:.1%} of the cells), {} faces of which {} wall faces; step threshold {:.2f} m, vertical error &lt;= {:.3f} m</source>
            <translation>{} Zellen -&gt; {} Eckpunkte ({:.1%} der Zellen), {} Dreiecke, davon {} Wanddreiecke; Sprungschwelle {:.2f} m, Höhenfehler &lt;= {:.3f} m</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="60" />
            <source>Orient images (bundle block adjustment)</source>
            <translation>Bilder orientieren (Bündelblockausgleichung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="93" />
            <source>Image files (instead of a folder)</source>
            <translation>Bilddateien (statt eines Ordners)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="99" />
            <source>Interior orientation file (optional)</source>
            <translation>Datei der inneren Orientierung (optional)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="102" />
            <source>Output CRS</source>
            <translation>Ausgabe-KBS</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="106" />
            <source>Working resolution (max image side, px)</source>
            <translation>Arbeitsauflösung (größte Bildseite, px)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="116" />
            <source>Features per image</source>
            <translation>Merkmale pro Bild</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="125" />
            <source>Self-calibration</source>
            <translation>Selbstkalibrierung</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="137" />
            <source>Report (HTML)</source>
            <translation>Bericht (HTML)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="138" />
            <source>HTML files (*.html)</source>
            <translation>HTML-Dateien (*.html)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="154" />
            <source>Tie points</source>
            <translation>Verknüpfungspunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="160" />
            <source>GCP and check point residuals</source>
            <translation>Residuen der Pass- und Kontrollpunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="173" />
            <source>Give either IMAGES (a folder) or IMAGE_FILES, not both</source>
            <translation>Geben Sie entweder IMAGES (einen Ordner) oder IMAGE_FILES an, nicht beides</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="183" />
            <source>IMAGES: give an image folder or a list of image files</source>
            <translation>IMAGES: geben Sie einen Bildordner oder eine Liste von Bilddateien an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="225" />
            <source>Registered {} of {} images; sigma0 {:.3f} px</source>
            <translation>{} von {} Bildern orientiert; Sigma0 {:.3f} px</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="198" />
            <source>{} control and {} check points</source>
            <translation>{} Pass- und {} Kontrollpunkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="176" />
            <source>IMAGES: {} is not a folder</source>
            <translation>IMAGES: {} ist kein Ordner</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="38" />
            <source>Dense matching (OSGM)</source>
            <translation>Dichte Bildzuordnung (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="307" />
            <source>DSM (OSGM)</source>
            <translation>DOM (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="86" />
            <source>Extent (default: the area seen by the images)</source>
            <translation>Ausdehnung (Standard: der von den Bildern gesehene Bereich)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="92" />
            <source>Resolution (m; empty or 0 = median ground sample distance)</source>
            <translation>Auflösung (m; leer oder 0 = mittlere Bodenpixelgröße)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="102" />
            <source>Height step of the search (m; empty or 0 = the resolution)</source>
            <translation>Höhenschritt der Suche (m; leer oder 0 = die Auflösung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="112" />
            <source>Lowest height searched (m; empty = automatic)</source>
            <translation>Niedrigste gesuchte Höhe (m; leer = automatisch)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="121" />
            <source>Highest height searched (m; empty = automatic)</source>
            <translation>Höchste gesuchte Höhe (m; leer = automatisch)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="129" />
            <source>Coarse surface bounding the search per cell (DSM/DTM)</source>
            <translation>Grobe Oberfläche, die die Suche je Zelle begrenzt (DOM/DGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="135" />
            <source>Aggregation paths</source>
            <translation>Aggregationspfade</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="143" />
            <source>Oblique images</source>
            <translation>Schrägbilder</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="151" />
            <source>Penalty P1, one height step (cost units; empty = default)</source>
            <translation>Strafterm P1, ein Höhenschritt (Kosteneinheiten; leer = Standard)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="162" />
            <source>Penalty P2, larger height jumps (cost units; empty = default)</source>
            <translation>Strafterm P2, größere Höhensprünge (Kosteneinheiten; leer = Standard)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="173" />
            <source>Images per tile (at most)</source>
            <translation>Bilder pro Kachel (höchstens)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="183" />
            <source>Tile size (cells)</source>
            <translation>Kachelgröße (Zellen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="195" />
            <source>Confidence [0, 1]</source>
            <translation>Konfidenz [0, 1]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="200" />
            <source>Orthoimage (matching colours)</source>
            <translation>Orthobild (Farben der Zuordnung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="206" />
            <source>Point cloud</source>
            <translation>Punktwolke</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="231" />
            <source>EXTENT: the extent is empty</source>
            <translation>EXTENT: die Ausdehnung ist leer</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="310" />
            <source>Confidence (OSGM)</source>
            <translation>Konfidenz (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="313" />
            <source>Orthoimage (OSGM)</source>
            <translation>Orthobild (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="144" />
            <source>none: one nadir reference system</source>
            <translation>none: ein Nadir-Referenzsystem</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="144" />
            <source>auto: extra systems for obliques</source>
            <translation>auto: zusätzliche Systeme für Schrägbilder</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="244" />
            <source>ORIENTATION: the file {!r} does not exist</source>
            <translation>ORIENTATION: die Datei {!r} existiert nicht</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="256" />
            <source>Z_MIN ({}) must be below Z_MAX ({})</source>
            <translation>Z_MIN ({}) muss unter Z_MAX ({}) liegen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="272" />
            <source>POINT_CLOUD: expected a .las or .laz file, got {!r}</source>
            <translation>POINT_CLOUD: .las- oder .laz-Datei erwartet, erhalten: {!r}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="251" />
            <source>{}: must be positive (or empty), got {}</source>
            <translation>{}: muss positiv (oder leer) sein, erhalten: {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="262" />
            <source>Z_SURFACE: expected a raster file (GeoTIFF), got {!r}</source>
            <translation>Z_SURFACE: Rasterdatei (GeoTIFF) erwartet, erhalten: {!r}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="29" />
            <source>Photos to true orthophoto (whole pipeline)</source>
            <translation>Fotos zum True Orthophoto (gesamte Prozesskette)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="103" />
            <source>DSM (filtered)</source>
            <translation>DOM (gefiltert)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="106" />
            <source>True orthophoto</source>
            <translation>True Orthophoto</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="107" />
            <source>Occlusion mask</source>
            <translation>Verdeckungsmaske</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="108" />
            <source>Seamlines</source>
            <translation>Nahtlinien</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="83" />
            <source>Resolution of the DSM and the true orthophoto (m, 0 = ground sample distance)</source>
            <translation>Auflösung des DOM und des True Orthophotos (m, 0 = Bodenpixelgröße)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="92" />
            <source>Reuse an existing orientation.json in the output folder</source>
            <translation>Eine vorhandene orientation.json im Ausgabeordner wiederverwenden</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="123" />
            <source>IMAGES: give the folder of the photos</source>
            <translation>IMAGES: geben Sie den Ordner der Fotos an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="139" />
            <source>OUTPUT_FOLDER: give a folder for the products</source>
            <translation>OUTPUT_FOLDER: geben Sie einen Ordner für die Produkte an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="149" />
            <source>RESOLUTION: expected a positive number of metres or 0</source>
            <translation>RESOLUTION: positive Anzahl Meter oder 0 erwartet</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="189" />
            <source>DSM (TruOrtho)</source>
            <translation>DOM (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="190" />
            <source>True orthophoto (TruOrtho)</source>
            <translation>True Orthophoto (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="191" />
            <source>Occlusion (TruOrtho)</source>
            <translation>Verdeckung (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="192" />
            <source>Seamlines (TruOrtho)</source>
            <translation>Nahtlinien (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="173" />
            <source>Tiles ran on: {}</source>
            <translation>Kacheln berechnet auf: {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="172" />
            <source>{}: {:.1f} s, peak {:.0f} MB; {}</source>
            <translation>{}: {:.1f} s, Spitze {:.0f} MB; {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="39" />
            <source>DSM to point cloud (LAS/LAZ + EPT)</source>
            <translation>DOM in Punktwolke (LAS/LAZ + EPT)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="95" />
            <source>Merge point clouds (reference systems)</source>
            <translation>Punktwolken zusammenführen (Referenzsysteme)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="27" />
            <source>LAZ (compressed) (*.laz);;LAS (*.las)</source>
            <translation>LAZ (komprimiert) (*.laz);;LAS (*.las)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="51" />
            <source>DSM</source>
            <translation>DOM</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="53" />
            <source>Orthoimage for point colours</source>
            <translation>Orthobild für die Punktfarben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="62" />
            <source>EPT dataset folder (opens in QGIS without PDAL)</source>
            <translation>EPT-Datensatzordner (öffnet in QGIS ohne PDAL)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="67" />
            <source>EPT ept.json</source>
            <translation>EPT ept.json</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="68" />
            <source>Points</source>
            <translation>Punkte</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="110" />
            <source>Point clouds (LAS/LAZ)</source>
            <translation>Punktwolken (LAS/LAZ)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="116" />
            <source>Thin duplicates on a voxel grid (m; empty = keep all)</source>
            <translation>Duplikate auf einem Voxelgitter ausdünnen (m; leer = alle behalten)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="123" />
            <source>Merged point cloud</source>
            <translation>Zusammengeführte Punktwolke</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="87" />
            <source>{} points written to {}</source>
            <translation>{} Punkte nach {} geschrieben</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="150" />
            <source>{} points from {} files ({} after thinning)</source>
            <translation>{} Punkte aus {} Dateien ({} nach dem Ausdünnen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="89" />
            <source>EPT dataset: {} (add it as a point cloud layer)</source>
            <translation>EPT-Datensatz: {} (als Punktwolken-Layer hinzufügen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="93" />
            <source>Surface: DSM raster or mesh</source>
            <translation>Oberfläche: DOM-Raster oder Dreiecksnetz</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="98" />
            <source>Extent (default: the surface's)</source>
            <translation>Ausdehnung (Standard: die der Oberfläche)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="103" />
            <source>Resolution (CRS units; 0 = the surface's cell size)</source>
            <translation>Auflösung (KBS-Einheiten; 0 = Zellgröße der Oberfläche)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="110" />
            <source>Output CRS (default: the orientation's)</source>
            <translation>Ausgabe-KBS (Standard: das der Orientierung)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="114" />
            <source>Colour correction</source>
            <translation>Farbausgleich</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="120" />
            <source>Remove vignetting (with the colour correction)</source>
            <translation>Vignettierung entfernen (mit der Farbkorrektur)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="129" />
            <source>Maximum off-nadir viewing angle (degrees)</source>
            <translation>Größter Blickwinkel zum Nadir (Grad)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="139" />
            <source>Blend width across seamlines (cells)</source>
            <translation>Überblendungsbreite an den Nahtlinien (Zellen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="160" />
            <source>Compression of the orthophoto</source>
            <translation>Kompression des Orthophotos</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="173" />
            <source>JPEG quality</source>
            <translation>JPEG-Qualität</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="185" />
            <source>Source image index</source>
            <translation>Index des Quellbilds</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="196" />
            <source>Seamlines (source image regions)</source>
            <translation>Nahtlinien (Bereiche der Quellbilder)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="211" />
            <source>SURFACE: give a DSM raster or a mesh file</source>
            <translation>SURFACE: geben Sie ein DOM-Raster oder eine Netzdatei an</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="94" />
            <source>Surfaces (*.tif *.tiff *.vrt *.ply *.obj);;All files (*.*)</source>
            <translation>Oberflächen (*.tif *.tiff *.vrt *.ply *.obj);;Alle Dateien (*.*)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="247" />
            <source>{} x {} cells, {} images used, coverage {:.2%}, {} cells seen by no image</source>
            <translation>{} x {} Zellen, {} Bilder verwendet, Abdeckung {:.2%}, {} Zellen von keinem Bild gesehen</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="162" />
            <source>DEFLATE (lossless, read by every GIS)</source>
            <translation>DEFLATE (verlustfrei, von jedem GIS gelesen)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="163" />
            <source>ZSTD (lossless, fastest to write, larger)</source>
            <translation>ZSTD (verlustfrei, am schnellsten geschrieben, größer)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="164" />
            <source>LZW (lossless)</source>
            <translation>LZW (verlustfrei)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="165" />
            <source>JPEG (lossy, 8-bit RGB images only; alpha becomes a mask)</source>
            <translation>JPEG (verlustbehaftet, nur 8-Bit-RGB-Bilder; Alpha wird zur Maske)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="254" />
            <source>colour correction ({}): disagreement between photos, median {:.2f} -&gt; {:.2f}</source>
            <translation>Farbkorrektur ({}): Abweichung zwischen den Fotos, Median {:.2f} -&gt; {:.2f}</translation>
        </message>
        <message>
            <location filename="../processing/feedback.py" line="86" />
            <source>Cancelled by the user</source>
            <translation>Vom Benutzer abgebrochen</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="12" />
            <source>JPEG photos smear colour over a few pixels across roof outlines, where roof and ground are about as bright (the brightness cannot restore it). Within 3 cells of the surface's height steps, a cell's colour (not its brightness) can be taken from the cells of its own surface farther from the step. checked (the default): only where the cell's colour is already nearer its own surface's than the other side's, so that a DSM from image matching, whose outlines may be a cell or two off, does not get roof colours painted on the ground. surface: every such cell, for a surface whose outlines are exact (a LiDAR DSM, a building model). off: the mosaic's colours as sampled. RGB images only.</source>
            <translation>JPEG-Fotos verschmieren die Farbe über einige Pixel quer zu Dachkanten, wo Dach und Boden etwa gleich hell sind (die Helligkeit kann sie nicht wiederherstellen). Innerhalb von 3 Zellen um die Höhensprünge der Oberfläche kann die Farbe einer Zelle (nicht ihre Helligkeit) aus den Zellen ihrer eigenen Fläche weiter vom Sprung entfernt übernommen werden. checked (Voreinstellung): nur wo die Farbe der Zelle schon näher an der ihrer eigenen Fläche liegt als an der der anderen Seite, damit ein DOM aus Bildzuordnung, dessen Umrisse eine oder zwei Zellen daneben liegen können, keine Dachfarben auf den Boden gemalt bekommt. surface: jede solche Zelle, für eine Oberfläche mit exakten Umrissen (ein LiDAR-DOM, ein Gebäudemodell). off: die Farben des Mosaiks wie abgetastet. Nur RGB-Bilder.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="23" />
            <source>Address of the Dask scheduler for EXECUTOR = scheduler: tls://host:8786, or the path of a scheduler file; empty = the environment variable TRUORTHO_DASK_SCHEDULER. Security: a Dask scheduler executes any code its clients send, so it must never be reachable unauthenticated. Use TLS with certificates for a remote scheduler (configured in Dask's configuration, distributed.comm.tls), or an SSH tunnel to 127.0.0.1; a plain tcp:// address that is not on this computer is refused.</source>
            <translation>Adresse des Dask-Schedulers für EXECUTOR = scheduler: tls://host:8786 oder der Pfad einer Scheduler-Datei; leer = die Umgebungsvariable TRUORTHO_DASK_SCHEDULER. Sicherheit: Ein Dask-Scheduler führt jeden Code aus, den seine Clients senden, und darf daher nie ohne Authentifizierung erreichbar sein. Für einen entfernten Scheduler TLS mit Zertifikaten verwenden (in der Dask-Konfiguration, distributed.comm.tls) oder einen SSH-Tunnel nach 127.0.0.1; eine einfache tcp://-Adresse, die nicht auf diesem Rechner liegt, wird abgelehnt.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="35" />
            <source>Imports the orientation of an image block (interior and exterior orientation of every image, sparse points) from COLMAP, Orthority or OpenSfM/ODM files into TruOrtho's orientation JSON, and writes a layer of projection centres and a layer of image footprints. Conventions (camera axes, rotations, pixel origin) are converted at import; see docs/FORMATS.md.</source>
            <translation>Importiert die Orientierung eines Bildverbands (innere und äußere Orientierung jedes Bildes, dünne Punktwolke) aus COLMAP-, Orthority- oder OpenSfM/ODM-Dateien in das Orientierungs-JSON von TruOrtho und schreibt einen Layer der Projektionszentren und einen Layer der Bildabdeckungen. Konventionen (Kameraachsen, Rotationen, Pixelursprung) werden beim Import umgerechnet; siehe docs/FORMATS.md.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="43" />
            <source>COLMAP text model (cameras.txt, images.txt or points3D.txt; the folder is used, with an optional georef.json {"crs": ..., "offset": [E, N, H]}), Orthority exterior CSV (filename, x, y, z, omega, phi, kappa[, camera]; degrees), OpenSfM/ODM reconstruction.json, or a TruOrtho orientation JSON.</source>
            <translation>COLMAP-Textmodell (cameras.txt, images.txt oder points3D.txt; verwendet wird der Ordner, mit einer optionalen georef.json {"crs": ..., "offset": [E, N, H]}), Orthority-CSV der äußeren Orientierung (filename, x, y, z, omega, phi, kappa[, camera]; Grad), OpenSfM/ODM-reconstruction.json oder ein TruOrtho-Orientierungs-JSON.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="48" />
            <source>Orthority interior parameter file (YAML or JSON); required with a CSV input.</source>
            <translation>Orthority-Parameterdatei der inneren Orientierung (YAML oder JSON); bei einer CSV-Eingabe erforderlich.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="49" />
            <source>CRS of the input coordinates when the file does not state it (CSV without .prj, COLMAP without georef.json); target CRS for OpenSfM's topocentric frame.</source>
            <translation>KBS der Eingabekoordinaten, wenn die Datei es nicht angibt (CSV ohne .prj, COLMAP ohne georef.json); Ziel-KBS für das topozentrische System von OpenSfM.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="51" />
            <source>Folder holding the images; every image of the block must be present there.</source>
            <translation>Ordner mit den Bildern; jedes Bild des Verbands muss dort vorhanden sein.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="52" />
            <source>Optional ground control: point layer with 'name', 'role' (gcp|check), PointZ or a 'z' field, optional 'sigma_xy'/'sigma_z' in metres. Reprojected to the orientation's CRS.</source>
            <translation>Optionale Passpunkte: Punktlayer mit 'name', 'role' (gcp|check), PointZ oder einem Feld 'z', optional 'sigma_xy'/'sigma_z' in Metern. Wird in das KBS der Orientierung umprojiziert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="54" />
            <source>Image measurements of the GCPs: table with 'gcp', 'image', 'x', 'y' in pixels ((0, 0) = centre of the top-left pixel).</source>
            <translation>Bildmessungen der Passpunkte: Tabelle mit 'gcp', 'image', 'x', 'y' in Pixeln ((0, 0) = Mitte des linken oberen Pixels).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="56" />
            <source>Height (in the CRS) of the plane the footprints are drawn on; default the median height of the sparse points, or of the GCPs, or 0.</source>
            <translation>Höhe (im KBS) der Ebene, auf der die Bildabdeckungen gezeichnet werden; Standard ist die mittlere Höhe (Median) der dünnen Punktwolke, sonst der Passpunkte, sonst 0.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="58" />
            <source>The orientation JSON (TruOrtho format, version 1).</source>
            <translation>Das Orientierungs-JSON (TruOrtho-Format, Version 1).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="59" />
            <source>Optional: projection centres as PointZ with name, camera, x, y, z, omega, phi, kappa (degrees); skipped when not given.</source>
            <translation>Optional: Projektionszentren als PointZ mit name, camera, x, y, z, omega, phi, kappa (Grad); entfällt, wenn nicht angegeben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="61" />
            <source>Image footprints on the horizontal plane at FOOTPRINT_HEIGHT.</source>
            <translation>Bildabdeckungen auf der horizontalen Ebene in Höhe FOOTPRINT_HEIGHT.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="66" />
            <source>Exports a TruOrtho orientation JSON to a COLMAP text model (cameras.txt, images.txt, points3D.txt and georef.json) or to Orthority frame-camera files (exterior.csv with a .prj sidecar and interior.yaml).</source>
            <translation>Exportiert ein TruOrtho-Orientierungs-JSON in ein COLMAP-Textmodell (cameras.txt, images.txt, points3D.txt und georef.json) oder in Orthority-Dateien für Rahmenkameras (exterior.csv mit einer .prj-Begleitdatei und interior.yaml).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="71" />
            <source>A TruOrtho orientation JSON.</source>
            <translation>Ein TruOrtho-Orientierungs-JSON.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="72" />
            <source>colmap or opk (Orthority CSV + interior file).</source>
            <translation>colmap oder opk (Orthority-CSV + Datei der inneren Orientierung).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="73" />
            <source>Folder the files are written to (created if needed).</source>
            <translation>Ordner, in den die Dateien geschrieben werden (wird bei Bedarf angelegt).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="78" />
            <source>Reads an ODM/OpenSfM gcp_list.txt (first line EPSG code, PROJ string or 'WGS84 UTM nnX'; then 'X Y Z px py image [name]') into a GCP point layer and an observation table, the two inputs ground control takes everywhere in TruOrtho.</source>
            <translation>Liest eine ODM/OpenSfM-gcp_list.txt (erste Zeile EPSG-Code, PROJ-String oder 'WGS84 UTM nnX'; dann 'X Y Z px py image [name]') in einen Passpunkt-Punktlayer und eine Beobachtungstabelle ein, die beiden Eingaben, die Passpunkte überall in TruOrtho benötigen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="83" />
            <source>The gcp_list.txt file.</source>
            <translation>Die Datei gcp_list.txt.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="84" />
            <source>Comma-separated GCP names to mark as check points (role 'check').</source>
            <translation>Kommagetrennte Passpunktnamen, die als Kontrollpunkte markiert werden (Rolle 'check').</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="85" />
            <source>Default planimetric standard deviation of the GCP coordinates, metres.</source>
            <translation>Standardabweichung der Lage der Passpunktkoordinaten (Standardwert), Meter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="86" />
            <source>Default height standard deviation of the GCP coordinates, metres.</source>
            <translation>Standardabweichung der Höhe der Passpunktkoordinaten (Standardwert), Meter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="87" />
            <source>Optional CRS to reproject the GCPs to (default: the file's CRS).</source>
            <translation>Optionales KBS, in das die Passpunkte umprojiziert werden (Standard: das KBS der Datei).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="88" />
            <source>GCP point layer (PointZ): name, role, z, sigma_xy, sigma_z.</source>
            <translation>Passpunkt-Punktlayer (PointZ): name, role, z, sigma_xy, sigma_z.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="89" />
            <source>Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the top-left pixel, as in gcp_list.txt).</source>
            <translation>Beobachtungstabelle: gcp, image, x, y (Pixel, (0, 0) = Mitte des linken oberen Pixels, wie in gcp_list.txt).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="95" />
            <source>Finds ground targets in every photo of a folder and writes an observation table with a score per measurement. ArUco markers are found anywhere; the GCP is the marker's centre (intersection of the diagonals of its outer corners), refined by least-squares matching of the ideal marker. Circular and checkerboard (X) targets are searched near the positions an orientation predicts for the GCPs, then refined the same way. Measurements with a low score are kept and flagged, never dropped.</source>
            <translation>Findet Bodenmarken in jedem Foto eines Ordners und schreibt eine Beobachtungstabelle mit einer Bewertung je Messung. ArUco-Marker werden überall gefunden; der Passpunkt ist die Mitte des Markers (Schnittpunkt der Diagonalen seiner äußeren Ecken), verfeinert durch Kleinste-Quadrate-Zuordnung des idealen Markers. Kreisförmige und Schachbrettmarken (X) werden nahe den Positionen gesucht, die eine Orientierung für die Passpunkte vorhersagt, und ebenso verfeinert. Messungen mit niedriger Bewertung werden behalten und markiert, nie verworfen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="103" />
            <source>Folder of the photos (jpg, png, tif, jp2, bmp).</source>
            <translation>Ordner der Fotos (jpg, png, tif, jp2, bmp).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="104" />
            <source>ArUco markers, circular targets (a dark disc on a light ground or the reverse) or checkerboard targets (two dark and two light quadrants).</source>
            <translation>ArUco-Marker, kreisförmige Marken (eine dunkle Scheibe auf hellem Grund oder umgekehrt) oder Schachbrettmarken (zwei dunkle und zwei helle Quadranten).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="106" />
            <source>The ArUco dictionary the markers were printed from.</source>
            <translation>Das ArUco-Wörterbuch, aus dem die Marker gedruckt wurden.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="107" />
            <source>ArUco only: marker ID to GCP name, e.g. 0=GCP1,1=GCP2. With a GCP layer, every name must be in it.</source>
            <translation>Nur ArUco: Marker-ID zu Passpunktname, z. B. 0=GCP1,1=GCP2. Mit einem Passpunktlayer muss jeder Name darin vorkommen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="109" />
            <source>Circular and checkerboard targets: the orientation (TruOrtho JSON) of the photos, used to predict where each GCP appears.</source>
            <translation>Kreisförmige und Schachbrettmarken: die Orientierung (TruOrtho-JSON) der Fotos, mit der vorhergesagt wird, wo jeder Passpunkt erscheint.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="111" />
            <source>Point layer of the GCPs ('name' field; PointZ or a 'z' field) whose positions are predicted; for ArUco it only checks the names of MARKER_IDS.</source>
            <translation>Punktlayer der Passpunkte (Feld 'name'; PointZ oder ein Feld 'z'), deren Positionen vorhergesagt werden; bei ArUco prüft er nur die Namen von MARKER_IDS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="113" />
            <source>Circular and checkerboard targets are searched this many pixels around their predicted positions.</source>
            <translation>Kreisförmige und Schachbrettmarken werden in diesem Abstand (Pixel) um ihre vorhergesagten Positionen gesucht.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="115" />
            <source>Measurements scoring lower (normalised cross-correlation of the ideal target with the photo, 0 to 1) are flagged 'low score'.</source>
            <translation>Messungen mit niedrigerer Bewertung (normierte Kreuzkorrelation der idealen Marke mit dem Foto, 0 bis 1) werden als 'low score' markiert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="117" />
            <source>Refine every centre by least-squares matching of the ideal target (gives the standard deviations).</source>
            <translation>Jede Mitte durch Kleinste-Quadrate-Zuordnung der idealen Marke verfeinern (liefert die Standardabweichungen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="119" />
            <source>Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the top-left pixel), score, sigma_x, sigma_y (pixels, empty when the refinement failed) and flag (ok, low score, refinement failed: reason).</source>
            <translation>Beobachtungstabelle: gcp, image, x, y (Pixel, (0, 0) = Mitte des Pixels oben links), score, sigma_x, sigma_y (Pixel, leer, wenn die Verfeinerung fehlschlug) und flag (ok, low score, refinement failed: Grund).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="126" />
            <source>Orients a block of overlapping photos: SIFT features at a working resolution, pair selection (exhaustive for small blocks, EXIF GNSS footprints, or a low-resolution retrieval pass), robust two-view geometry, tie-point tracks decimated on a grid by multiplicity, incremental reconstruction and a bundle block adjustment written for TruOrtho (collinearity equations with Brown distortion, Levenberg-Marquardt with the Schur complement, Huber loss, self-calibration). Ground control fixes the datum (7-parameter similarity, then weighted GCP observations); check points never enter the adjustment and are reported with per-axis RMSE. Without GCPs, EXIF GNSS positions serve as weighted priors; without either the block stays in an arbitrary frame.</source>
            <translation>Orientiert einen Verband überlappender Fotos: SIFT-Merkmale in einer Arbeitsauflösung, Paarauswahl (vollständig bei kleinen Verbänden, über EXIF-GNSS-Bildabdeckungen oder einen Suchlauf in niedriger Auflösung), robuste Zweibildgeometrie, Verknüpfungspunktspuren, auf einem Raster nach Vielfachheit ausgedünnt, inkrementelle Rekonstruktion und eine für TruOrtho geschriebene Bündelblockausgleichung (Kollinearitätsgleichungen mit Brown-Verzeichnung, Levenberg-Marquardt mit dem Schur-Komplement, Huber-Verlustfunktion, Selbstkalibrierung). Passpunkte legen das Datum fest (7-Parameter-Ähnlichkeitstransformation, dann gewichtete Passpunktbeobachtungen); Kontrollpunkte gehen nie in die Ausgleichung ein und werden mit dem RMSE je Achse berichtet. Ohne Passpunkte dienen EXIF-GNSS-Positionen als gewichtete Vorinformation; ohne beides bleibt der Verband in einem beliebigen System.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="136" />
            <source>Folder of the images (non-image files are skipped with a warning in the report).</source>
            <translation>Ordner der Bilder (Nicht-Bilddateien werden mit einer Warnung im Bericht übersprungen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="137" />
            <source>The image files, instead of a folder.</source>
            <translation>Die Bilddateien, statt eines Ordners.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="138" />
            <source>Interior orientation: an Orthority interior file (YAML/JSON) or a text file with the 3x3 matrix K, taken as a calibration and held fixed. Without it: EXIF focal length and sensor size, else f = 1.2 x max(w, h), refined by self-calibration.</source>
            <translation>Innere Orientierung: eine Orthority-Datei der inneren Orientierung (YAML/JSON) oder eine Textdatei mit der 3x3-Matrix K, als Kalibrierung übernommen und festgehalten. Ohne sie: EXIF-Brennweite und Sensorgröße, sonst f = 1,2 x max(w, h), verfeinert durch Selbstkalibrierung.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="141" />
            <source>Ground control and check points: point layer with 'name', 'role' (gcp|check), PointZ or 'z', optional 'sigma_xy'/'sigma_z' (metres). Reprojected to CRS.</source>
            <translation>Pass- und Kontrollpunkte: Punktlayer mit 'name', 'role' (gcp|check), PointZ oder 'z', optional 'sigma_xy'/'sigma_z' (Meter). Wird in CRS umprojiziert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="143" />
            <source>Image measurements of the GCPs: table with 'gcp', 'image' (file name), 'x', 'y' (pixels, (0, 0) = centre of the top-left pixel).</source>
            <translation>Bildmessungen der Passpunkte: Tabelle mit 'gcp', 'image' (Dateiname), 'x', 'y' (Pixel, (0, 0) = Mitte des linken oberen Pixels).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="145" />
            <source>CRS of the output (default: the GCP layer's, else the UTM zone of the EXIF GNSS positions).</source>
            <translation>KBS der Ausgabe (Standard: das des Passpunktlayers, sonst die UTM-Zone der EXIF-GNSS-Positionen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="147" />
            <source>Larger image side at which features are detected, pixels.</source>
            <translation>Längere Bildseite, auf der die Merkmale detektiert werden, Pixel.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="148" />
            <source>Features kept per image.</source>
            <translation>Pro Bild behaltene Merkmale.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="149" />
            <source>Estimate f, cx, cy, k1, k2, p1, p2 in the adjustment when no CAMERA file is given (else hold the prior interior orientation).</source>
            <translation>f, cx, cy, k1, k2, p1, p2 in der Ausgleichung schätzen, wenn keine CAMERA-Datei angegeben ist (sonst die vorgegebene innere Orientierung festhalten).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="151" />
            <source>The adjusted orientation (TruOrtho JSON).</source>
            <translation>Die ausgeglichene Orientierung (TruOrtho-JSON).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="152" />
            <source>HTML report (and a JSON file of the same name): sigma0, image RMS, per-image residuals, GCP and check point tables, residual vector plots, tie-point multiplicity histogram, block overview. Optional: by default written beside ORIENTATION as name_report.html.</source>
            <translation>HTML-Bericht (und eine gleichnamige JSON-Datei): Sigma0, Bild-RMS, Residuen je Bild, Tabellen der Pass- und Kontrollpunkte, Residuenvektor-Grafiken, Histogramm der Vielfachheit der Verknüpfungspunkte, Verbandsübersicht. Optional: standardmäßig neben ORIENTATION als name_report.html geschrieben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="156" />
            <source>Optional: projection centres (PointZ) with omega, phi, kappa; skipped when not given.</source>
            <translation>Optional: Projektionszentren (PointZ) mit omega, phi, kappa; entfällt, wenn nicht angegeben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="158" />
            <source>Tie points (PointZ) with multiplicity, mean reprojection error and colour.</source>
            <translation>Verknüpfungspunkte (PointZ) mit Vielfachheit, mittlerem Rückprojektionsfehler und Farbe.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="159" />
            <source>GCPs and check points with dX, dY, dZ (adjusted or triangulated minus surveyed).</source>
            <translation>Pass- und Kontrollpunkte mit dX, dY, dZ (ausgeglichen bzw. trianguliert minus gemessen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="165" />
            <source>The whole chain from photos to a true orthophoto in one run: image orientation with the ground control (bundle block adjustment), dense matching in object space (OSGM), DSM filtering, a mesh, and the true orthophoto with its occlusion mask and seamlines, plus one HTML report (block overview, sigma0, GCP and check point tables, residual plot, DSM hillshade, true-orthophoto preview, time and memory per stage). The products are written to OUTPUT_FOLDER with fixed names: orientation.json, report.html, dsm.tif, pointcloud.laz, mesh.ply, trueortho.tif, occlusion.tif, seamlines.gpkg (and the raw DSM, confidence and orthoimage of the matching).</source>
            <translation>Die gesamte Prozesskette von Fotos zum True Orthophoto in einem Lauf: Bildorientierung mit den Passpunkten (Bündelblockausgleichung), dichte Bildzuordnung im Objektraum (OSGM), DOM-Filterung, eine Vermaschung und das True Orthophoto mit seiner Verdeckungsmaske und den Nahtlinien, dazu ein HTML-Bericht (Verbandsübersicht, Sigma0, Tabellen der Pass- und Kontrollpunkte, Residuengrafik, DOM-Schummerung, Vorschau des True Orthophotos, Zeit und Speicher je Schritt). Die Produkte werden mit festen Namen in OUTPUT_FOLDER geschrieben: orientation.json, report.html, dsm.tif, pointcloud.laz, mesh.ply, trueortho.tif, occlusion.tif, seamlines.gpkg (sowie das rohe DOM, die Konfidenz und das Orthobild der Zuordnung).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="175" />
            <source>Folder of the photos (JPEG, TIFF, PNG...); other files are skipped.</source>
            <translation>Ordner der Fotos (JPEG, TIFF, PNG...); andere Dateien werden übersprungen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="176" />
            <source>Optional interior orientation (Orthority YAML/JSON or a 3x3 K text file), held fixed; otherwise EXIF priors refined by self-calibration.</source>
            <translation>Optionale innere Orientierung (Orthority-YAML/JSON oder eine Textdatei mit der 3x3-Matrix K), festgehalten; sonst EXIF-Vorwerte, verfeinert durch Selbstkalibrierung.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="178" />
            <source>Optional point layer of ground control and check points (fields name, role gcp|check, optional z, sigma_xy, sigma_z), as for Orient images. Needed for a georeferenced product unless the photos carry EXIF GNSS positions.</source>
            <translation>Optionaler Punktlayer der Pass- und Kontrollpunkte (Felder name, role gcp|check, optional z, sigma_xy, sigma_z), wie bei Bilder orientieren. Für ein georeferenziertes Produkt erforderlich, sofern die Fotos keine EXIF-GNSS-Positionen enthalten.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="181" />
            <source>Table of the GCP image measurements (gcp, image, x, y), given with GCPS.</source>
            <translation>Tabelle der Bildmessungen der Passpunkte (gcp, image, x, y), zusammen mit GCPS anzugeben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="182" />
            <source>CRS of the products; default the GCP layer's CRS.</source>
            <translation>KBS der Produkte; Standard ist das KBS des Passpunktlayers.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="183" />
            <source>Cell size of the DSM and the true orthophoto in metres; 0 = the median ground sample distance of the near-nadir images.</source>
            <translation>Zellgröße des DOM und des True Orthophotos in Metern; 0 = mittlere Bodenpixelgröße (Median) der nadirnahen Bilder.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="185" />
            <source>Skip the orientation when OUTPUT_FOLDER already holds orientation.json (e.g. to rerun matching and the orthophoto with another resolution).</source>
            <translation>Die Orientierung überspringen, wenn OUTPUT_FOLDER bereits eine orientation.json enthält (z. B. um Zuordnung und Orthophoto mit einer anderen Auflösung erneut zu rechnen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="187" />
            <source>Most cameras store JPEG colour at half the resolution of the brightness (4:2:0 or 4:2:2, read from each file's header), so colours smear across building outlines. When on, the colour edges of such images are restored from the brightness before they are sampled at full resolution. Other images are not changed.</source>
            <translation>Die meisten Kameras speichern die Farbe von JPEGs mit halber Auflösung der Helligkeit (4:2:0 oder 4:2:2, aus dem Kopf jeder Datei gelesen), so dass Farben über Gebäudeumrisse verschmieren. Wenn eingeschaltet, werden die Farbkanten solcher Bilder aus der Helligkeit wiederhergestellt, bevor sie in voller Auflösung abgetastet werden. Andere Bilder bleiben unverändert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="192" />
            <source>Where the tiles of dense matching, DSM filtering and the true orthophoto are computed, by one executor for the three stages (a local cluster starts once); the products are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the photos and OUTPUT_FOLDER at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The orientation, the mesh and the report are computed in QGIS's process. The address is checked before the orientation starts; the scheduler is first contacted by dense matching.</source>
            <translation>Wo die Kacheln der dichten Bildzuordnung, der DOM-Filterung und des True Orthophotos berechnet werden, durch einen Executor für alle drei Schritte (ein lokaler Cluster startet nur einmal); die Produkte sind bei jeder Wahl identisch. inprocess: im Prozess von QGIS, eine Kachel nach der anderen auf allen Kernen (Standard). local: ein Dask-Cluster aus Worker-Prozessen auf diesem Rechner, der nur auf 127.0.0.1 lauscht (ein Worker je Kern, je mit Speichergrenze). scheduler: ein bestehender Dask-Cluster, gegeben durch SCHEDULER_ADDRESS; seine Worker müssen die Fotos und OUTPUT_FOLDER unter denselben Pfaden lesen (gemeinsamer Speicher) und TruOrtho installiert haben. Fällt ein Worker aus, berechnen die anderen seine Kacheln neu. Orientierung, Dreiecksnetz und Bericht werden im Prozess von QGIS berechnet. Die Adresse wird vor dem Start der Orientierung geprüft; der Scheduler wird erstmals von der dichten Bildzuordnung kontaktiert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="203" />
            <source>Folder of the products (created when missing; existing products are replaced). It holds only products: orientation.json (adjusted orientation), report.html and report.json (the quality report and its data), dsm_raw.tif (DSM as matched, before filtering), confidence.tif (matching confidence 0 to 1), orthoimage.tif (colour of each DSM cell from the matching, not a true orthophoto), dsm.tif (filtered DSM), pointcloud.laz, mesh.ply, trueortho.tif, source_index.tif (which photo each true-orthophoto cell comes from), occlusion.tif and seamlines.gpkg. Caches (compiled kernels, image features) are kept in the per-user cache folder (environment variable TRUORTHO_CACHE_DIR; truortho:environment shows and clears it).</source>
            <translation>Ordner der Produkte (wird angelegt, falls er fehlt; vorhandene Produkte werden ersetzt). Er enthält nur Produkte: orientation.json (ausgeglichene Orientierung), report.html und report.json (der Qualitätsbericht und seine Daten), dsm_raw.tif (DOM wie zugeordnet, vor der Filterung), confidence.tif (Zuordnungskonfidenz 0 bis 1), orthoimage.tif (Farbe jeder DOM-Zelle aus der Zuordnung, kein True-Orthophoto), dsm.tif (gefiltertes DOM), pointcloud.laz, mesh.ply, trueortho.tif, source_index.tif (aus welchem Foto jede True-Orthophoto-Zelle stammt), occlusion.tif und seamlines.gpkg. Caches (kompilierte Kernel, Bildmerkmale) liegen im benutzereigenen Cache-Ordner (Umgebungsvariable TRUORTHO_CACHE_DIR; truortho:environment zeigt und leert ihn).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="212" />
            <source>orientation.json: the adjusted orientation.</source>
            <translation>orientation.json: die ausgeglichene Orientierung.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="213" />
            <source>report.html (and report.json): the quality report of the run.</source>
            <translation>report.html (und report.json): der Qualitätsbericht des Laufs.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="214" />
            <source>dsm.tif: the filtered DSM (float32, nodata -9999).</source>
            <translation>dsm.tif: das gefilterte DOM (float32, NoData -9999).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="215" />
            <source>pointcloud.laz: the matched points with colour and confidence.</source>
            <translation>pointcloud.laz: die zugeordneten Punkte mit Farbe und Konfidenz.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="216" />
            <source>mesh.ply: 2.5D mesh of the filtered DSM with vertical walls and vertex colours.</source>
            <translation>mesh.ply: 2,5D-Dreiecksnetz des gefilterten DOM mit senkrechten Wänden und Eckpunktfarben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="217" />
            <source>trueortho.tif: the true orthophoto (bands of the photos + alpha, COG).</source>
            <translation>trueortho.tif: das True Orthophoto (Kanäle der Fotos + Alpha, COG).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="218" />
            <source>occlusion.tif: 1 where no photo sees the surface.</source>
            <translation>occlusion.tif: 1, wo kein Foto die Oberfläche sieht.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="219" />
            <source>seamlines.gpkg: one polygon per source photo.</source>
            <translation>seamlines.gpkg: ein Polygon je Quellfoto.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="224" />
            <source>Dense image matching in object space (OSGM): computes a DSM directly on a ground grid from the oriented images, without rectification or pairwise depth maps. For every tile of the grid the images that see it (at most MAX_IMAGES) are resampled onto the horizontal plane of every search height (voxels of RESOLUTION x RESOLUTION x Z_STEP); a matching cost from all of them per cell and height is aggregated by semi-global matching along 8 or 16 paths (penalty P1 for a change of one height step, P2 for larger jumps, lowered across image edges), and each cell takes the height of least aggregated cost, refined between steps, with a confidence in [0, 1]. Matching runs coarse to fine over an image pyramid, by tiles, with progress and cancel. Cells without a reliable match are nodata (filter and fill them with truortho:dsmfilter). Optionally writes the confidence, an orthoimage coloured from the matched images, and a point cloud; with OBLIQUE = auto, groups of oblique images are matched in extra reference systems along their viewing directions, whose points (facades) go to the point cloud.</source>
            <translation>Dichte Bildzuordnung im Objektraum (OSGM): berechnet ein DOM direkt auf einem Bodenraster aus den orientierten Bildern, ohne Epipolarentzerrung oder paarweise Tiefenkarten. Für jede Kachel des Rasters werden die Bilder, die sie sehen (höchstens MAX_IMAGES), auf die horizontale Ebene jeder Suchhöhe umgebildet (Voxel von RESOLUTION x RESOLUTION x Z_STEP); ein Zuordnungskostenwert aus allen diesen Bildern je Zelle und Höhe wird durch Semi-Global Matching entlang 8 oder 16 Pfaden aggregiert (Strafterm P1 für eine Änderung um einen Höhenschritt, P2 für größere Sprünge, an Bildkanten verringert), und jede Zelle erhält die Höhe mit den geringsten aggregierten Kosten, zwischen den Schritten verfeinert, mit einer Konfidenz in [0, 1]. Die Zuordnung läuft grob-zu-fein über eine Bildpyramide, kachelweise, mit Fortschrittsanzeige und Abbruchmöglichkeit. Zellen ohne zuverlässige Zuordnung sind NoData (mit truortho:dsmfilter filtern und füllen). Optional werden die Konfidenz, ein aus den zugeordneten Bildern eingefärbtes Orthobild und eine Punktwolke geschrieben; mit OBLIQUE = auto werden Gruppen von Schrägbildern in zusätzlichen Referenzsystemen entlang ihrer Blickrichtungen zugeordnet, deren Punkte (Fassaden) in die Punktwolke gehen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="238" />
            <source>Orientation JSON (from Orient images or Import orientation) with a projected CRS (metres) and at least two images, which must be on disk.</source>
            <translation>Orientierungs-JSON (aus Bilder orientieren oder Orientierung importieren) mit einem projizierten KBS (Meter) und mindestens zwei Bildern, die auf der Festplatte vorhanden sein müssen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="240" />
            <source>Area to match (reprojected to the orientation's CRS); default the extent of the sparse points (1-99 %), else the union of the near-nadir image footprints. It must intersect the area the images see.</source>
            <translation>Zuzuordnender Bereich (in das KBS der Orientierung umprojiziert); Standard ist die Ausdehnung der dünnen Punktwolke (1-99 %), sonst die Vereinigung der Bildabdeckungen der nadirnahen Bilder. Er muss den von den Bildern gesehenen Bereich schneiden.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="243" />
            <source>Cell size of the DSM, metres; empty or 0 = the median ground sample distance of the near-nadir images.</source>
            <translation>Zellgröße des DOM, Meter; leer oder 0 = mittlere Bodenpixelgröße (Median) der nadirnahen Bilder.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="245" />
            <source>Height step between two search planes, metres; empty or 0 = the resolution. A larger step (1.5 x the resolution) is about 10 % faster, with crisper building edges and fewer holes, and noisier on flat ground.</source>
            <translation>Höhenschritt zwischen zwei Suchebenen, Meter; leer oder 0 = die Auflösung. Ein größerer Schritt (das 1,5-Fache der Auflösung) ist etwa 10 % schneller, mit schärferen Gebäudekanten und weniger Löchern, und auf ebenem Gelände verrauschter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="248" />
            <source>Lowest height searched (world Z, the orientation's vertical datum); empty = from the sparse points (0.5 % percentile minus a margin), else from the GCP heights. Must be below Z_MAX.</source>
            <translation>Niedrigste gesuchte Höhe (Welt-Z, das Höhendatum der Orientierung); leer = aus der dünnen Punktwolke (0,5-%-Perzentil minus einem Rand), sonst aus den Passpunkthöhen. Muss unter Z_MAX liegen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="251" />
            <source>Highest height searched; empty = from the sparse points (99.5 % percentile plus a margin), else half the flying height above the highest GCP. Always kept below the cameras. Without sparse points or GCPs give Z_MIN and Z_MAX.</source>
            <translation>Höchste gesuchte Höhe; leer = aus der dünnen Punktwolke (99,5-%-Perzentil plus einem Rand), sonst die halbe Flughöhe über dem höchsten Passpunkt. Bleibt immer unterhalb der Kameras. Ohne dünne Punktwolke oder Passpunkte Z_MIN und Z_MAX angeben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="254" />
            <source>Optional coarse DSM or DTM raster: the search at each cell is bounded by the lowest and highest height of its neighbourhood plus a margin, which speeds up matching and avoids wrong heights on rough terrain.</source>
            <translation>Optionales grobes DOM- oder DGM-Raster: die Suche an jeder Zelle wird durch die niedrigste und höchste Höhe ihrer Nachbarschaft plus einen Rand begrenzt, was die Zuordnung beschleunigt und falsche Höhen in rauem Gelände vermeidet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="257" />
            <source>Number of aggregation directions of semi-global matching: 16 (the default) or 8 (about 6 % faster; the hillshade of natural terrain then shows a fine cross-hatch along the grid's axes and diagonals).</source>
            <translation>Anzahl der Aggregationsrichtungen des Semi-Global-Matchings: 16 (Standard) oder 8 (etwa 6 % schneller; die Schummerung natürlichen Geländes zeigt dann ein feines Gittermuster entlang der Achsen und Diagonalen des Rasters).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="260" />
            <source>none: one nadir reference system (the DSM). auto: groups of oblique images also get reference systems along their viewing directions, whose points go to the point cloud with their 'system' id (without a POINT_CLOUD output they are skipped: the DSM is the same).</source>
            <translation>none: ein Nadir-Referenzsystem (das DOM). auto: Gruppen von Schrägbildern erhalten zusätzlich Referenzsysteme entlang ihrer Blickrichtungen, deren Punkte mit ihrer 'system'-Kennung in die Punktwolke gehen (ohne Ausgabe POINT_CLOUD werden sie übersprungen: das DOM ist dasselbe).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="263" />
            <source>Penalty for a change of one height step between neighbouring cells, in cost units (unrelated image windows cost 1023); empty = 256.</source>
            <translation>Strafterm für eine Änderung um einen Höhenschritt zwischen benachbarten Zellen, in Kosteneinheiten (unabhängige Bildfenster kosten 1023); leer = 256.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="265" />
            <source>Penalty for a larger height jump, above P1 and at most 3072; empty = 2048 (a jump then needs contrary evidence from two cells).</source>
            <translation>Strafterm für einen größeren Höhensprung, über P1 und höchstens 3072; leer = 2048 (ein Sprung erfordert dann Gegenevidenz aus zwei Zellen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="267" />
            <source>Largest number of images matched per tile (best coverage first, then the most nadir; more only where fewer would leave part of the tile with under 2 views); memory and time grow with it.</source>
            <translation>Größte Anzahl pro Kachel zugeordneter Bilder (beste Abdeckung zuerst, dann die nadirnächsten; mehr nur, wo weniger einen Teil der Kachel mit weniger als 2 Ansichten ließen); Speicherbedarf und Rechenzeit wachsen damit.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="270" />
            <source>Tile side in cells; memory grows with its square, the number of search heights and MAX_IMAGES.</source>
            <translation>Kachelseite in Zellen; der Speicherbedarf wächst mit ihrem Quadrat, der Anzahl der Suchhöhen und MAX_IMAGES.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="272" />
            <source>Where the tiles are matched; the DSM and confidence are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the images at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. Finished tiles are kept beside the DSM (DSM.tif.tiles) until the run ends, so a rerun with the same inputs and parameters after a crash reuses them.</source>
            <translation>Wo die Kacheln zugeordnet werden; DOM und Konfidenz sind bei jeder Wahl identisch. inprocess: im Prozess von QGIS, eine Kachel nach der anderen auf allen Kernen (Standard). local: ein Dask-Cluster aus Worker-Prozessen auf diesem Rechner, der nur auf 127.0.0.1 lauscht (ein Worker je Kern, je mit Speichergrenze). scheduler: ein bestehender Dask-Cluster, gegeben durch SCHEDULER_ADDRESS; seine Worker müssen die Bilder unter denselben Pfaden lesen (gemeinsamer Speicher) und TruOrtho installiert haben. Fällt ein Worker aus, berechnen die anderen seine Kacheln neu. Fertige Kacheln werden bis zum Ende des Laufs neben dem DOM aufbewahrt (DSM.tif.tiles), sodass ein erneuter Lauf mit denselben Eingaben und Parametern nach einem Absturz sie wiederverwendet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="281" />
            <source>The raw DSM: GeoTIFF, float32, in the orientation's CRS, nodata -9999.</source>
            <translation>Das rohe DOM: GeoTIFF, float32, im KBS der Orientierung, NoData -9999.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="282" />
            <source>Optional confidence GeoTIFF (float32 in [0, 1], nodata -1) on the DSM grid, for truortho:dsmfilter.</source>
            <translation>Optionales Konfidenz-GeoTIFF (float32 in [0, 1], NoData -1) auf dem DOM-Raster, für truortho:dsmfilter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="284" />
            <source>Optional RGB orthoimage GeoTIFF (uint8, 0 = no data) on the DSM grid, coloured from the matched images; not a true orthophoto (use truortho:trueortho for that).</source>
            <translation>Optionales RGB-Orthobild als GeoTIFF (uint8, 0 = keine Daten) auf dem DOM-Raster, aus den zugeordneten Bildern eingefärbt; kein True Orthophoto (dafür truortho:trueortho verwenden).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="286" />
            <source>Optional point cloud (.laz or .las; LAS 1.4 with colours, 'confidence' and 'system', the reference system of each point).</source>
            <translation>Optionale Punktwolke (.laz oder .las; LAS 1.4 mit Farben, 'confidence' und 'system', dem Referenzsystem jedes Punktes).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="288" />
            <source>JSON: grid size, resolution, height step and range (and where it came from), pyramid levels, tiles, completeness, mean confidence, reference systems, time.</source>
            <translation>JSON: Rastergröße, Auflösung, Höhenschritt und -bereich (und woher er stammt), Pyramidenstufen, Kacheln, Vollständigkeit, mittlere Konfidenz, Referenzsysteme, Zeit.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="294" />
            <source>Computes a true orthophoto from oriented images and a surface (a DSM raster such as OSGM's, or a PLY/OBJ mesh): every cell is coloured from an image that really sees it, found with a depth buffer of the surface per image (DSM cells as flat tops with vertical walls at height steps, or the mesh's triangles; frustum and back-face culling). Among the images that see a cell the one with the finest effective ground resolution (distance and incidence on the surface) is preferred; roofs are textured from one image each and seamlines follow height discontinuities and avoid places where the images disagree (label smoothing), with feathering across seams only between images that both see the cells. Per-image colour corrections (a gain/offset per RGB channel for white balance and exposure, then one in CIE L*a*b*; per-band gain/offset for non-RGB data) are estimated by least squares from cells seen by several images. Cells no image sees get alpha 0 and appear in the occlusion mask. Any band count and data type of the images is kept (RGB, 16-bit panchromatic, thermal). Processing runs by tiles with bounded memory; progress and cancel per tile.</source>
            <translation>Berechnet ein True Orthophoto aus orientierten Bildern und einer Oberfläche (einem DOM-Raster wie dem von OSGM oder einem PLY/OBJ-Dreiecksnetz): jede Zelle wird aus einem Bild eingefärbt, das sie wirklich sieht, ermittelt mit einem Tiefenpuffer der Oberfläche je Bild (DOM-Zellen als flache Dächer mit senkrechten Wänden an Höhensprüngen, oder die Dreiecke des Netzes; Frustum- und Rückseiten-Culling). Unter den Bildern, die eine Zelle sehen, wird dasjenige mit der feinsten effektiven Bodenauflösung (Entfernung und Einfallswinkel auf der Oberfläche) bevorzugt; Dächer werden jeweils aus einem einzigen Bild texturiert, und die Nahtlinien folgen Höhensprüngen und meiden Stellen, an denen die Bilder nicht übereinstimmen (Label-Glättung), mit Überblendung über die Nähte nur zwischen Bildern, die beide die Zellen sehen. Farbkorrekturen je Bild (Verstärkung/Versatz je RGB-Kanal für Weißabgleich und Belichtung, danach in CIE L*a*b*; Verstärkung/Versatz je Kanal für Nicht-RGB-Daten) werden per Ausgleichung nach kleinsten Quadraten aus Zellen geschätzt, die mehrere Bilder sehen. Zellen, die kein Bild sieht, erhalten Alpha 0 und erscheinen in der Verdeckungsmaske. Kanalanzahl und Datentyp der Bilder bleiben erhalten (RGB, 16-Bit-panchromatisch, thermal). Die Verarbeitung läuft kachelweise mit begrenztem Speicher; Fortschritt und Abbruch je Kachel.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="309" />
            <source>Orientation JSON (from Orient images or Import orientation); its images must be on disk.</source>
            <translation>Orientierungs-JSON (aus Bilder orientieren oder Orientierung importieren); seine Bilder müssen auf der Festplatte vorhanden sein.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="311" />
            <source>DSM GeoTIFF (any CRS; resampled onto the output grid by nearest neighbour) or a PLY/OBJ mesh. Heights must use the orientation's vertical datum. It must cover the extent.</source>
            <translation>DOM-GeoTIFF (beliebiges KBS; per nächstem Nachbarn auf das Ausgaberaster umgebildet) oder ein PLY/OBJ-Dreiecksnetz. Die Höhen müssen das Höhendatum der Orientierung verwenden. Es muss die Ausdehnung abdecken.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="313" />
            <source>Output extent; default the surface's extent.</source>
            <translation>Ausgabeausdehnung; Standard ist die Ausdehnung der Oberfläche.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="314" />
            <source>Output cell size in units of the output CRS; 0 = the DSM's cell size.</source>
            <translation>Ausgabezellgröße in Einheiten des Ausgabe-KBS; 0 = Zellgröße des DOM.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="315" />
            <source>Output CRS; default the orientation's. When it differs, the computation runs on the output grid and cell centres are transformed to the orientation's CRS (images are resampled once).</source>
            <translation>Ausgabe-KBS; Standard ist das der Orientierung. Weicht es ab, läuft die Berechnung auf dem Ausgaberaster, und die Zellmittelpunkte werden in das KBS der Orientierung transformiert (die Bilder werden nur einmal umgebildet).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="318" />
            <source>Estimate and apply per-image colour corrections before mosaicking.</source>
            <translation>Farbkorrekturen je Bild vor der Mosaikbildung schätzen und anwenden.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="319" />
            <source>With the colour correction: estimate a radial darkening towards the image corners per camera from the overlaps and remove it first. Images without vignetting get a factor of about 1; switch it off for images already corrected in processing.</source>
            <translation>Mit der Farbkorrektur: je Kamera eine radiale Abdunklung zu den Bildecken aus den Überlappungen schätzen und zuerst entfernen. Bilder ohne Vignettierung erhalten einen Faktor von etwa 1; für bereits bei der Entwicklung korrigierte Bilder ausschalten.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="327" />
            <source>Largest off-nadir angle of the viewing ray (degrees) for an image to texture a cell; also bounds how far outside a tile occluders are searched.</source>
            <translation>Größter Winkel des Sehstrahls zum Nadir (Grad), unter dem ein Bild eine Zelle texturieren darf; begrenzt auch, wie weit außerhalb einer Kachel nach verdeckenden Objekten gesucht wird.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="329" />
            <source>Width of the feathering across seamlines, in cells (0 = hard seams).</source>
            <translation>Breite der Überblendung an den Nahtlinien, in Zellen (0 = harte Nähte).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="330" />
            <source>Tile side in cells; memory grows with its square and the images per tile.</source>
            <translation>Kachelseite in Zellen; der Speicherbedarf wächst mit ihrem Quadrat und den Bildern pro Kachel.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="331" />
            <source>Compression of the orthophoto. DEFLATE (the default), ZSTD and LZW are lossless: DEFLATE gives the smallest files and every GIS reads it; ZSTD (level 1) writes about twice as fast and about 9 % larger (GDAL 2.3 or later reads it); LZW is for older readers. JPEG is lossy (about a fifth of the size), for 8-bit RGB images only: RGB is stored as YCbCr with halved colour resolution, so colours blur across sharp edges such as building outlines (deliver and view with it; measure on a lossless one), and the alpha band becomes the file's internal mask. The source index and occlusion mask always stay lossless.</source>
            <translation>Kompression des Orthophotos. DEFLATE (Standard), ZSTD und LZW sind verlustfrei: DEFLATE ergibt die kleinsten Dateien und jedes GIS liest es; ZSTD (Stufe 1) schreibt etwa doppelt so schnell und etwa 9 % größer (lesbar ab GDAL 2.3); LZW ist für ältere Leseprogramme. JPEG ist verlustbehaftet (etwa ein Fünftel der Größe), nur für 8-Bit-RGB-Bilder: RGB wird als YCbCr mit halbierter Farbauflösung gespeichert, sodass Farben über scharfe Kanten wie Gebäudeumrisse verschwimmen (zum Ausliefern und Ansehen; gemessen wird an einer verlustfreien Datei), und das Alphaband wird zur internen Maske der Datei. Quellbildindex und Verdeckungsmaske bleiben immer verlustfrei.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="338" />
            <source>JPEG quality (1-100) when COMPRESSION is JPEG.</source>
            <translation>JPEG-Qualität (1-100), wenn COMPRESSION JPEG ist.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="339" />
            <source>Where the tiles of the mosaic are computed; the true orthophoto, source index, occlusion mask and seamlines are identical with every choice. inprocess: in QGIS's process, the independent tiles of a wave in parallel threads (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the images and the surface at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The colour correction (on a decimated grid) is estimated in QGIS's process. Finished tiles are kept in a folder beside the output (its name plus '.tiles') until the run succeeds, so a rerun with the same inputs and parameters after a crash reuses them.</source>
            <translation>Wo die Kacheln des Mosaiks berechnet werden; True Orthophoto, Quellbildindex, Verdeckungsmaske und Nahtlinien sind bei jeder Wahl identisch. inprocess: im Prozess von QGIS, die unabhängigen Kacheln einer Welle parallel in Threads (Standard). local: ein Dask-Cluster aus Worker-Prozessen auf diesem Rechner, der nur auf 127.0.0.1 lauscht (ein Worker je Kern, je mit Speichergrenze). scheduler: ein bestehender Dask-Cluster, gegeben durch SCHEDULER_ADDRESS; seine Worker müssen die Bilder und die Oberfläche unter denselben Pfaden lesen (gemeinsamer Speicher) und TruOrtho installiert haben. Fällt ein Worker aus, berechnen die anderen seine Kacheln neu. Der Farbausgleich (auf einem ausgedünnten Raster) wird im Prozess von QGIS geschätzt. Fertige Kacheln werden bis zum erfolgreichen Ende des Laufs in einem Ordner neben der Ausgabe aufbewahrt (ihr Name plus '.tiles'), sodass ein erneuter Lauf mit denselben Eingaben und Parametern nach einem Absturz sie wiederverwendet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="351" />
            <source>GeoTIFF with the images' bands and data type plus an alpha band (an internal mask with JPEG compression), tiled, with overviews, Cloud-Optimized GeoTIFF layout.</source>
            <translation>GeoTIFF mit den Bändern und dem Datentyp der Bilder plus einem Alphaband (bei JPEG-Kompression eine interne Maske), gekachelt, mit Übersichten, im Cloud-Optimized-GeoTIFF-Layout.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="353" />
            <source>Int16 GeoTIFF: index (0-based, orientation order) of the image each cell comes from; -1 = nodata.</source>
            <translation>Int16-GeoTIFF: Index (ab 0, Reihenfolge der Orientierung) des Bildes, aus dem jede Zelle stammt; -1 = NoData.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="355" />
            <source>UInt8 GeoTIFF: 1 where no image sees the cell, 0 where seen, 255 where the surface has no data.</source>
            <translation>UInt8-GeoTIFF: 1, wo kein Bild die Zelle sieht, 0, wo sie gesehen wird, 255, wo die Oberfläche keine Daten hat.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="357" />
            <source>Polygons, one feature per source image: the cells it colours (image_index, image, cells, area).</source>
            <translation>Polygone, ein Objekt pro Quellbild: die Zellen, die es einfärbt (image_index, image, cells, area).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="363" />
            <source>Cleans a raw DSM (e.g. the dense-matching DSM of TruOrtho's OSGM step) tile by tile: snaps the cells of blurred height steps to the nearer side, removes outliers (cells that depart from the confidence-weighted median of their window by more than the threshold and have too few neighbours at their height, so roof edges and corners survive), fills holes up to a maximum width by harmonic interpolation (holes at the foot of walls from the ground side only; wider holes stay nodata and are reported), and optionally smooths planar surfaces without blurring their edges. Optionally derives a terrain model (DTM) by SMRF-style ground filtering and the normalised DSM (height above terrain). Outputs keep the input's CRS, grid and nodata; the statistics (removed outliers, filled cells, remaining holes) are returned and logged.</source>
            <translation>Bereinigt ein rohes DOM (z. B. das DOM der dichten Bildzuordnung aus dem OSGM-Schritt von TruOrtho) kachelweise: schiebt die Zellen verschliffener Höhensprünge auf die nähere Seite, entfernt Ausreißer (Zellen, die um mehr als die Schwelle vom konfidenzgewichteten Median ihres Fensters abweichen und zu wenige Nachbarn auf ihrer Höhe haben, sodass Dachkanten und Ecken erhalten bleiben), füllt Lücken bis zu einer Höchstbreite durch harmonische Interpolation (Lücken am Fuß von Wänden nur von der Bodenseite aus; breitere Lücken bleiben NoData und werden gemeldet) und glättet optional ebene Flächen, ohne ihre Kanten zu verwischen. Optional wird ein Geländemodell (DGM) durch Bodenfilterung nach Art von SMRF abgeleitet sowie das normalisierte DOM (Höhe über Gelände). Die Ausgaben behalten KBS, Raster und NoData der Eingabe; die Statistik (entfernte Ausreißer, gefüllte Zellen, verbleibende Lücken) wird zurückgegeben und protokolliert.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="374" />
            <source>Raw DSM: single-band raster with a projected CRS (metres); its nodata cells are holes.</source>
            <translation>Rohes DOM: einkanaliges Raster mit einem projizierten KBS (Meter); seine NoData-Zellen sind Lücken.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="375" />
            <source>Optional confidence raster in [0, 1] (OSGM's CONFIDENCE): cells below the minimum confidence are removed, less confident cells must agree better with their neighbours, and the median is weighted by confidence.</source>
            <translation>Optionales Konfidenzraster in [0, 1] (CONFIDENCE von OSGM): Zellen unter der Mindestkonfidenz werden entfernt, weniger zuverlässige Zellen müssen besser mit ihren Nachbarn übereinstimmen, und der Median wird mit der Konfidenz gewichtet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="378" />
            <source>Largest departure from the neighbourhood median, metres (empty: 4 x the resolution).</source>
            <translation>Größte Abweichung vom Median der Nachbarschaft, Meter (leer: 4 x die Auflösung).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="380" />
            <source>Side of the median window in cells (odd); a second pass uses twice the window.</source>
            <translation>Seitenlänge des Medianfensters in Zellen (ungerade); ein zweiter Durchlauf verwendet das doppelte Fenster.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="382" />
            <source>Neighbours within the threshold of a cell's height that keep it although it departs from the median (edges, corners, thin structures).</source>
            <translation>Nachbarn innerhalb der Schwelle um die Höhe einer Zelle, die sie erhalten, obwohl sie vom Median abweicht (Kanten, Ecken, dünne Strukturen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="384" />
            <source>With a confidence raster: cells below this confidence are removed.</source>
            <translation>Mit einem Konfidenzraster: Zellen unter dieser Konfidenz werden entfernt.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="385" />
            <source>With a confidence raster: less confident cells are removed when they depart by more than the threshold from the median of the cells at least this confident in their 15 x 15 window (0: off).</source>
            <translation>Mit einem Konfidenzraster: weniger zuverlässige Zellen werden entfernt, wenn sie um mehr als die Schwelle vom Median der Zellen mit mindestens dieser Konfidenz in ihrem 15-x-15-Fenster abweichen (0: aus).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="388" />
            <source>Largest hole width (metres) that is interpolated; 0 fills nothing.</source>
            <translation>Größte Lückenbreite (Meter), die interpoliert wird; 0 füllt nichts.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="389" />
            <source>Height difference between two surfaces (a wall), metres: hole boundary cells that much above nearby boundary cells are not interpolated from.</source>
            <translation>Höhenunterschied zwischen zwei Oberflächen (eine Wand), Meter: Randzellen einer Lücke, die so viel höher als benachbarte Randzellen liegen, werden nicht zur Interpolation verwendet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="391" />
            <source>Snap the cells of blurred height steps (between the two levels of their 5 x 5 window) to the nearer level.</source>
            <translation>Die Zellen verschliffener Höhensprünge (zwischen den beiden Niveaus ihres 5-x-5-Fensters) auf das nähere Niveau schieben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="393" />
            <source>Replace cells by a local plane fitted to the neighbours at their height (flat and pitched roofs, streets); steps stay sharp.</source>
            <translation>Zellen durch eine lokale Ebene ersetzen, die an die Nachbarn auf ihrer Höhe angepasst ist (Flach- und Schrägdächer, Straßen); Sprünge bleiben scharf.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="395" />
            <source>Radius of the smoothing neighbourhood, cells.</source>
            <translation>Radius der Glättungsnachbarschaft, Zellen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="396" />
            <source>Neighbours within this height of a cell belong to its surface, metres (empty: 2.5 x the resolution).</source>
            <translation>Nachbarn innerhalb dieser Höhe um eine Zelle gehören zu ihrer Oberfläche, Meter (leer: 2,5 x die Auflösung).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="398" />
            <source>Cell size of the ground filter, metres (empty: max(1 m, the DSM resolution)); the DTM is written on the DSM grid.</source>
            <translation>Zellgröße des Bodenfilters, Meter (leer: max(1 m, DOM-Auflösung)); das DGM wird auf dem DOM-Raster geschrieben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="400" />
            <source>Largest opening radius of the ground filter, metres: more than half the width of the largest building.</source>
            <translation>Größter Öffnungsradius des Bodenfilters, Meter: mehr als die halbe Breite des größten Gebäudes.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="402" />
            <source>Terrain slope (rise over run) the ground filter keeps as ground.</source>
            <translation>Geländeneigung (Höhe pro Strecke), die der Bodenfilter als Boden behält.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="403" />
            <source>Where the tiles are filtered; the filtered DSM and the statistics are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the DSM and the confidence raster at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The terrain model is computed in QGIS's process.</source>
            <translation>Wo die Kacheln gefiltert werden; gefiltertes DOM und Statistik sind bei jeder Wahl identisch. inprocess: im Prozess von QGIS, eine Kachel nach der anderen auf allen Kernen (Standard). local: ein Dask-Cluster aus Worker-Prozessen auf diesem Rechner, der nur auf 127.0.0.1 lauscht (ein Worker je Kern, je mit Speichergrenze). scheduler: ein bestehender Dask-Cluster, gegeben durch SCHEDULER_ADDRESS; seine Worker müssen das DOM und das Konfidenzraster unter denselben Pfaden lesen (gemeinsamer Speicher) und TruOrtho installiert haben. Fällt ein Worker aus, berechnen die anderen seine Kacheln neu. Das Geländemodell wird im Prozess von QGIS berechnet.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="411" />
            <source>Filtered DSM (GeoTIFF, float32).</source>
            <translation>Gefiltertes DOM (GeoTIFF, float32).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="412" />
            <source>Optional terrain model (GeoTIFF, float32, DSM grid).</source>
            <translation>Optionales Geländemodell (GeoTIFF, float32, DOM-Raster).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="413" />
            <source>Optional normalised DSM: DSM minus DTM, heights above the terrain.</source>
            <translation>Optionales normalisiertes DOM: DOM minus DGM, Höhen über dem Gelände.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="414" />
            <source>JSON: the filter statistics (and the ground filter's).</source>
            <translation>JSON: die Filterstatistik (und die des Bodenfilters).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="415" />
            <source>Cells removed as outliers or for low confidence.</source>
            <translation>Als Ausreißer oder wegen geringer Konfidenz entfernte Zellen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="416" />
            <source>Hole cells interpolated.</source>
            <translation>Interpolierte Lückenzellen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="417" />
            <source>Holes wider than MAX_HOLE, left as nodata.</source>
            <translation>Lücken, breiter als MAX_HOLE, als NoData belassen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="422" />
            <source>Builds a triangle mesh. From a DSM: a 2.5D mesh whose height steps are vertical walls (no triangle ever spans a step) and whose flat and smooth areas are decimated by a restricted quadtree with a guaranteed vertical error bound at every cell centre; vertex colours from an optional orthoimage. From a point cloud (LAS/LAZ or EPT, e.g. merged oblique matching): one 2.5D Delaunay mesh per reference system, seen along its viewing direction (overlapping layers where systems see the same surface; not watertight). Writes PLY (binary) or OBJ, in the CRS or in a local frame whose offset is recorded in the header; truortho:trueortho reads it as SURFACE.</source>
            <translation>Erzeugt eine Dreiecksvermaschung. Aus einem DOM: ein 2,5D-Netz, dessen Höhensprünge senkrechte Wände sind (kein Dreieck überspannt je einen Sprung) und dessen ebene und glatte Bereiche durch einen eingeschränkten Quadtree mit garantierter Höhenfehlerschranke an jedem Zellmittelpunkt ausgedünnt werden; Eckpunktfarben aus einem optionalen Orthobild. Aus einer Punktwolke (LAS/LAZ oder EPT, z. B. zusammengeführte Zuordnung von Schrägbildern): ein 2,5D-Delaunay-Netz je Referenzsystem, entlang seiner Blickrichtung gesehen (überlappende Schichten, wo Systeme dieselbe Oberfläche sehen; nicht wasserdicht). Schreibt PLY (binär) oder OBJ, im KBS oder in einem lokalen System, dessen Offset im Dateikopf vermerkt ist; truortho:trueortho liest es als SURFACE.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="431" />
            <source>DSM raster (projected CRS) or point cloud (.las, .laz, or an EPT ept.json).</source>
            <translation>DOM-Raster (projiziertes KBS) oder Punktwolke (.las, .laz oder eine EPT-ept.json).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="432" />
            <source>Optional orthoimage (RGB) for the vertex colours of a DSM mesh.</source>
            <translation>Optionales Orthobild (RGB) für die Eckpunktfarben eines DOM-Netzes.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="433" />
            <source>Largest vertical difference between mesh and DSM at any cell centre, metres (empty: half the DSM resolution).</source>
            <translation>Größter Höhenunterschied zwischen Netz und DOM an einem Zellmittelpunkt, Meter (leer: halbe DOM-Auflösung).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="435" />
            <source>Smallest height difference between neighbouring cells that becomes a wall, metres.</source>
            <translation>Kleinster Höhenunterschied zwischen benachbarten Zellen, der zur Wand wird, Meter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="436" />
            <source>Steepest slope kept as sloping triangles, degrees: the step threshold is max(MIN_STEP, resolution x tan(MAX_SLOPE)).</source>
            <translation>Steilste als geneigte Dreiecke erhaltene Neigung, Grad: die Sprungschwelle ist max(MIN_STEP, Auflösung x tan(MAX_SLOPE)).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="438" />
            <source>Largest block of cells one pair of triangles may cover (a power of two).</source>
            <translation>Größter Zellblock, den ein Dreieckspaar abdecken darf (eine Zweierpotenz).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="439" />
            <source>Point clouds: longest triangle edge, metres (empty: 4 x the median point spacing).</source>
            <translation>Punktwolken: längste Dreieckskante, Meter (leer: 4 x der mittlere Punktabstand).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="440" />
            <source>CRS: world coordinates (PLY doubles). Local: world minus an offset recorded as 'comment offset E N H' (PLY) or '# offset E N H' (OBJ), for viewers that need small numbers.</source>
            <translation>CRS: Weltkoordinaten (PLY-Doubles). Lokal: Welt minus einem Offset, vermerkt als 'comment offset E N H' (PLY) oder '# offset E N H' (OBJ), für Viewer, die kleine Zahlen benötigen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="442" />
            <source>The mesh: .ply (binary little-endian, 'comment crs ...') or .obj ('# crs ...', vertex colours as 'v x y z r g b').</source>
            <translation>Das Netz: .ply (binär, Little-Endian, 'comment crs ...') oder .obj ('# crs ...', Eckpunktfarben als 'v x y z r g b').</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="444" />
            <source>Number of vertices.</source>
            <translation>Anzahl der Eckpunkte.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="445" />
            <source>Number of triangles.</source>
            <translation>Anzahl der Dreiecke.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="446" />
            <source>Number of vertical wall triangles (DSM meshes).</source>
            <translation>Anzahl der senkrechten Wanddreiecke (DOM-Netze).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="451" />
            <source>Exports a DSM as a point cloud, one point per valid cell centre, with colours from an orthoimage and per-point confidence from a confidence raster: LAS 1.4 or LAZ (point format 7, CRS as WKT, extra dimensions 'confidence' and 'system' (the reference system), a TruOrtho VLR describing the reference systems), readable by PDAL, laspy, LAStools and CloudCompare. An Entwine Point Tile (EPT) dataset is written beside it: QGIS builds without PDAL (as Debian's QGIS 3.22) open it as a point cloud layer (menu Layer, Add Layer, Add Point Cloud Layer; choose ept.json).</source>
            <translation>Exportiert ein DOM als Punktwolke, ein Punkt je gültigem Zellmittelpunkt, mit Farben aus einem Orthobild und Konfidenz je Punkt aus einem Konfidenzraster: LAS 1.4 oder LAZ (Punktformat 7, KBS als WKT, Zusatzdimensionen 'confidence' und 'system' (das Referenzsystem), ein TruOrtho-VLR, der die Referenzsysteme beschreibt), lesbar mit PDAL, laspy, LAStools und CloudCompare. Daneben wird ein Entwine-Point-Tile-Datensatz (EPT) geschrieben: QGIS-Builds ohne PDAL (wie das QGIS 3.22 von Debian) öffnen ihn als Punktwolken-Layer (Menü Layer, Layer hinzufügen, Punktwolken-Layer hinzufügen; ept.json wählen).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="460" />
            <source>DSM raster with a projected CRS.</source>
            <translation>DOM-Raster mit einem projizierten KBS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="461" />
            <source>Optional orthoimage (RGB) for the point colours.</source>
            <translation>Optionales Orthobild (RGB) für die Punktfarben.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="462" />
            <source>Optional confidence raster in [0, 1], stored as the 'confidence' dimension.</source>
            <translation>Optionales Konfidenzraster in [0, 1], gespeichert als Dimension 'confidence'.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="463" />
            <source>The point cloud (.laz compressed, or .las).</source>
            <translation>Die Punktwolke (.laz komprimiert oder .las).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="464" />
            <source>Folder of the EPT dataset (ept.json, ept-data/, ept-hierarchy/); leave empty to skip.</source>
            <translation>Ordner des EPT-Datensatzes (ept.json, ept-data/, ept-hierarchy/); leer lassen, um ihn zu überspringen.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="465" />
            <source>Path of the EPT dataset's ept.json.</source>
            <translation>Pfad der ept.json des EPT-Datensatzes.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="466" />
            <source>Number of points written.</source>
            <translation>Anzahl der geschriebenen Punkte.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="471" />
            <source>Merges point clouds of several reference systems (e.g. the nadir and oblique systems of dense matching) into one LAS 1.4 / LAZ file, keeping each point's 'system' (files without it get the index of their file) and confidence; optionally thins duplicates on a voxel grid, keeping the most confident point of each voxel; optionally writes an EPT dataset for QGIS.</source>
            <translation>Führt Punktwolken mehrerer Referenzsysteme (z. B. das Nadir- und die Schrägsysteme der dichten Bildzuordnung) in einer LAS-1.4-/LAZ-Datei zusammen und behält dabei 'system' jedes Punktes (Dateien ohne dieses Attribut erhalten den Index ihrer Datei) und seine Konfidenz; dünnt optional Duplikate auf einem Voxelgitter aus und behält den zuverlässigsten Punkt jedes Voxels; schreibt optional einen EPT-Datensatz für QGIS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="477" />
            <source>LAS/LAZ files in one CRS.</source>
            <translation>LAS/LAZ-Dateien in einem KBS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="478" />
            <source>Voxel size for thinning, metres (empty: keep every point).</source>
            <translation>Voxelgröße für das Ausdünnen, Meter (leer: jeden Punkt behalten).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="479" />
            <source>The merged point cloud (.laz or .las).</source>
            <translation>Die zusammengeführte Punktwolke (.laz oder .las).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="480" />
            <source>Optional folder for an EPT dataset of the merged cloud.</source>
            <translation>Optionaler Ordner für einen EPT-Datensatz der zusammengeführten Wolke.</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="222" />
            <source>GCP</source>
            <translation>Passpunkt</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="330" />
            <source>Observation</source>
            <translation>Beobachtung</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="371" />
            <source>GCPS and OBSERVATIONS must be given together</source>
            <translation>GCPS und OBSERVATIONS müssen zusammen angegeben werden</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="54" />
            <source>QGIS cannot read the CRS {!r}</source>
            <translation>QGIS kann das KBS {!r} nicht lesen</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="185" />
            <source>{}: expected a finite number, got {!r}</source>
            <translation>{}: endliche Zahl erwartet, erhalten: {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="194" />
            <source>{} layer {!r} lacks the field(s) {}; expected fields: {}</source>
            <translation>Layer {} {!r}: es fehlen die Felder {}; erwartete Felder: {}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="313" />
            <source>Observation table {!r}, feature {}: sigma must be positive, got {}</source>
            <translation>Beobachtungstabelle {!r}, Objekt {}: sigma muss positiv sein, erhalten {}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="183" />
            <source>{}: expected a number, got {!r}</source>
            <translation>{}: Zahl erwartet, erhalten: {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="244" />
            <source>GCP layer {!r}: feature {} has no name</source>
            <translation>Passpunktlayer {!r}: Objekt {} hat keinen Namen</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="249" />
            <source>GCP layer {!r}: the name {!r} appears twice</source>
            <translation>Passpunktlayer {!r}: der Name {!r} kommt doppelt vor</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="255" />
            <source>GCP layer {!r}: GCP {!r} has no geometry</source>
            <translation>Passpunktlayer {!r}: Passpunkt {!r} hat keine Geometrie</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="263" />
            <source>GCP layer {!r}: GCP {!r} is not a single point</source>
            <translation>Passpunktlayer {!r}: Passpunkt {!r} ist kein Einzelpunkt</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="269" />
            <source>GCP layer {!r}: GCP {!r} has no height: use PointZ geometries or a 'z' field</source>
            <translation>Passpunktlayer {!r}: Passpunkt {!r} hat keine Höhe: verwenden Sie PointZ-Geometrien oder ein Feld 'z'</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="339" />
            <source>Observation table {!r}, feature {}: unknown GCP {!r}</source>
            <translation>Beobachtungstabelle {!r}, Objekt {}: unbekannter Passpunkt {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="345" />
            <source>Observation table {!r}, feature {}: unknown image {!r}</source>
            <translation>Beobachtungstabelle {!r}, Objekt {}: unbekanntes Bild {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="353" />
            <source>Observation table {!r}, feature {}: x and y are required</source>
            <translation>Beobachtungstabelle {!r}, Objekt {}: x und y sind erforderlich</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="283" />
            <source>GCP layer {!r}: GCP {!r} has role {!r}; expected 'gcp' or 'check'</source>
            <translation>Passpunktlayer {!r}: Passpunkt {!r} hat die Rolle {!r}; erwartet wird 'gcp' oder 'check'</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="296" />
            <source>GCP {!r}: sigmas must be positive</source>
            <translation>Passpunkt {!r}: Sigmas müssen positiv sein</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="59" />
            <source>TruOrtho</source>
            <translation>TruOrtho</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="62" />
            <source>TruOrtho {} — orientation, dense matching and true orthophotos</source>
            <translation>TruOrtho {} — Orientierung, dichte Bildzuordnung und True Orthophotos</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="96" />
            <source>TruOrtho model {} could not be loaded</source>
            <translation>TruOrtho-Modell {} konnte nicht geladen werden</translation>
        </message>
        <message>
            <location filename="../processing/styles.py" line="73" />
            <source>seen by no image</source>
            <translation>von keinem Bild gesehen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="212" />
            <source>Load measurements from a CSV table or gcp_list.txt</source>
            <translation>Messungen aus einer CSV-Tabelle oder gcp_list.txt laden</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="107" />
            <source>GCP measurements</source>
            <translation>GCP-Messungen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="140" />
            <source>Folder of the photos</source>
            <translation>Ordner der Fotos</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="144" />
            <source>Images</source>
            <translation>Bilder</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="148" />
            <source>GCP layer</source>
            <translation>GCP-Layer</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="151" />
            <source>Optional: orientation to predict the GCPs in the images</source>
            <translation>Optional: Orientierung, um die GCPs in den Bildern vorherzusagen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="161" />
            <source>Load</source>
            <translation>Laden</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="161" />
            <source>Read the images, the GCPs and the orientation</source>
            <translation>Bilder, GCPs und Orientierung einlesen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="165" />
            <source>Undo</source>
            <translation>Rückgängig</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="165" />
            <source>Undo (Ctrl+Z)</source>
            <translation>Rückgängig (Strg+Z)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="166" />
            <source>Redo</source>
            <translation>Wiederholen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="166" />
            <source>Redo (Ctrl+Shift+Z)</source>
            <translation>Wiederholen (Strg+Umschalt+Z)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="168" />
            <source>Delete</source>
            <translation>Löschen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="169" />
            <source>Delete the measurement of the current GCP in this image (Del)</source>
            <translation>Messung des aktuellen GCP in diesem Bild löschen (Entf)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="173" />
            <source>Refine</source>
            <translation>Verfeinern</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="174" />
            <source>Measure the current GCP in its other images by least-squares matching from this image's measurement (needs an orientation)</source>
            <translation>Den aktuellen GCP in seinen anderen Bildern per Kleinste-Quadrate-Zuordnung ausgehend von der Messung in diesem Bild messen (benötigt eine Orientierung)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="203" />
            <source>Click: place the current GCP; drag: pan; wheel: zoom</source>
            <translation>Klick: aktuellen GCP setzen; Ziehen: verschieben; Mausrad: zoomen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="257" />
            <source>Orientations (*.json *.txt);;All files (*)</source>
            <translation>Orientierungen (*.json *.txt);;Alle Dateien (*)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="361" />
            <source>predicted</source>
            <translation>vorhergesagt</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="361" />
            <source>not measured</source>
            <translation>nicht gemessen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="556" />
            <source>Save the observation table</source>
            <translation>Beobachtungstabelle speichern</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="556" />
            <source>CSV (*.csv)</source>
            <translation>CSV (*.csv)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="562" />
            <source>Save gcp_list.txt</source>
            <translation>gcp_list.txt speichern</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="563" />
            <source>gcp_list (*.txt)</source>
            <translation>gcp_list (*.txt)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="568" />
            <source>Open measurements</source>
            <translation>Messungen öffnen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="569" />
            <source>Observation tables (*.csv *.txt)</source>
            <translation>Beobachtungstabellen (*.csv *.txt)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="143" />
            <source>Choose the image folder</source>
            <translation>Bildordner wählen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="155" />
            <source>Choose an orientation file</source>
            <translation>Orientierungsdatei wählen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="194" />
            <source>Previous image (Page Up)</source>
            <translation>Vorheriges Bild (Bild auf)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="195" />
            <source>Next image (Page Down)</source>
            <translation>Nächstes Bild (Bild ab)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="196" />
            <source>Previous GCP (Ctrl+Page Up)</source>
            <translation>Vorheriger GCP (Strg+Bild auf)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="197" />
            <source>Next GCP (Ctrl+Page Down)</source>
            <translation>Nächster GCP (Strg+Bild ab)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="198" />
            <source>Fit</source>
            <translation>Einpassen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="198" />
            <source>Show the whole image (F)</source>
            <translation>Ganzes Bild zeigen (F)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="213" />
            <source>Open table…</source>
            <translation>Tabelle öffnen…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="215" />
            <source>Save table…</source>
            <translation>Tabelle speichern…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="215" />
            <source>Save the observation table (CSV)</source>
            <translation>Beobachtungstabelle speichern (CSV)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="218" />
            <source>Save gcp_list…</source>
            <translation>gcp_list speichern…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="218" />
            <source>Save as ODM gcp_list.txt</source>
            <translation>Als ODM-gcp_list.txt speichern</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="221" />
            <source>Add table layer</source>
            <translation>Tabellenlayer hinzufügen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="222" />
            <source>Keep the measurements as a table layer in the project: the saved CSV table, rewritten as you measure (a temporary layer until a table is saved)</source>
            <translation>Messungen als Tabellenlayer im Projekt behalten: die gespeicherte CSV-Tabelle, beim Messen laufend neu geschrieben (bis eine Tabelle gespeichert ist, ein temporärer Layer)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="280" />
            <source>Choose the folder of the photos first.</source>
            <translation>Zuerst den Ordner der Fotos wählen.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="283" />
            <source>Choose a GCP point layer first (fields: name, optional role and z).</source>
            <translation>Zuerst einen GCP-Punktlayer wählen (Felder: name, optional role und z).</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="308" />
            <source>{} GCPs, {} images</source>
            <translation>{} GCPs, {} Bilder</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="451" />
            <source>Load the images and the GCPs first.</source>
            <translation>Zuerst die Bilder und die GCPs laden.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="479" />
            <source>Refining needs an orientation: choose one and load again.</source>
            <translation>Verfeinern benötigt eine Orientierung: eine wählen und erneut laden.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="490" />
            <source>{} refined in {} images</source>
            <translation>{} in {} Bildern verfeinert</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="636" />
            <source>GCP observations</source>
            <translation>GCP-Beobachtungen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="310" />
            <source>; {} predicted positions</source>
            <translation>; {} vorhergesagte Positionen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="492" />
            <source>; not in {}</source>
            <translation>; nicht in {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="538" />
            <source>{} on {}: {} — {} measured, {} to do — zoom {:.2f}</source>
            <translation>{} in {}: {} — {} gemessen, {} offen — Zoom {:.2f}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="331" />
            <source>{}: X {:.3f}, Y {:.3f}, Z {:.3f}{}</source>
            <translation>{}: X {:.3f}, Y {:.3f}, Z {:.3f}{}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="332" />
            <source> (check point)</source>
            <translation> (Kontrollpunkt)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="487" />
            <source>Refinement failed: {}</source>
            <translation>Verfeinerung fehlgeschlagen: {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="487" />
            <source>no image matched</source>
            <translation>kein Bild zugeordnet</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="592" />
            <source>Saved {} measurements to {}</source>
            <translation>{} Messungen in {} gespeichert</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="617" />
            <source>Loaded {} measurements from {}</source>
            <translation>{} Messungen aus {} geladen</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="289" />
            <source>GCP layer {!r} has no point</source>
            <translation>GCP-Layer {!r} enthält keinen Punkt</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="393" />
            <source>Cannot read the image {}</source>
            <translation>Das Bild {} kann nicht gelesen werden</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="638" />
            <source>Cannot open {} as a table layer</source>
            <translation>{} kann nicht als Tabellenlayer geöffnet werden</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="15" />
            <source>&amp;TruOrtho</source>
            <translation>&amp;TruOrtho</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="18" />
            <source>Photos to true orthophoto (whole pipeline)…</source>
            <translation>Fotos zum True Orthophoto (gesamte Prozesskette)…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="19" />
            <source>Orient images…</source>
            <translation>Bilder orientieren…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="20" />
            <source>Dense matching (OSGM)…</source>
            <translation>Dichte Bildzuordnung (OSGM)…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="21" />
            <source>Filter DSM…</source>
            <translation>DOM filtern…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="22" />
            <source>DSM to mesh…</source>
            <translation>DOM zu Dreiecksnetz…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="23" />
            <source>True orthophoto…</source>
            <translation>True Orthophoto…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="105" />
            <source>GCP measurements in photos…</source>
            <translation>GCP-Messungen in Fotos…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="133" />
            <source>The algorithm {} is not available in this version.</source>
            <translation>Der Algorithmus {} ist in dieser Version nicht verfügbar.</translation>
        </message>
        <message>
            <source>none: one nadir reference system (the DSM). auto: groups of oblique images also get reference systems along their viewing directions, whose points go to the point cloud with their 'system' id.</source>
            <translation type="obsolete">none: ein Nadir-Referenzsystem (das DOM). auto: Gruppen von Schrägbildern erhalten zusätzlich Referenzsysteme entlang ihrer Blickrichtungen, deren Punkte mit ihrer 'system'-Kennung in die Punktwolke gehen.</translation>
        </message>
        <message>
            <source>Computes a true orthophoto from oriented images and a surface (a DSM raster such as OSGM's, or a PLY/OBJ mesh): every cell is coloured from an image that really sees it, found with a depth buffer of the surface per image (DSM cells as flat tops with vertical walls at height steps, or the mesh's triangles; frustum and back-face culling). Among the images that see a cell the one with the finest effective ground resolution (distance and incidence on the surface) is preferred; roofs are textured from one image each and seamlines follow height discontinuities and avoid places where the images disagree (label smoothing), with feathering across seams only between images that both see the cells. Per-image colour corrections in CIE L*a*b* (per-band gain/offset for non-RGB data) are estimated by least squares from cells seen by several images. Cells no image sees get alpha 0 and appear in the occlusion mask. Any band count and data type of the images is kept (RGB, 16-bit panchromatic, thermal). Processing runs by tiles with bounded memory; progress and cancel per tile.</source>
            <translation type="obsolete">Berechnet ein True Orthophoto aus orientierten Bildern und einer Oberfläche (einem DOM-Raster wie dem von OSGM oder einem PLY/OBJ-Dreiecksnetz): jede Zelle wird aus einem Bild eingefärbt, das sie wirklich sieht, ermittelt mit einem Tiefenpuffer der Oberfläche je Bild (DOM-Zellen als flache Dächer mit senkrechten Wänden an Höhensprüngen, oder die Dreiecke des Netzes; Frustum- und Rückseiten-Culling). Unter den Bildern, die eine Zelle sehen, wird dasjenige mit der feinsten effektiven Bodenauflösung (Entfernung und Einfallswinkel auf der Oberfläche) bevorzugt; Dächer werden jeweils aus einem einzigen Bild texturiert, und die Nahtlinien folgen Höhensprüngen und meiden Stellen, an denen die Bilder nicht übereinstimmen (Label-Glättung), mit Überblendung über die Nähte nur zwischen Bildern, die beide die Zellen sehen. Farbkorrekturen je Bild in CIE L*a*b* (Verstärkung/Versatz je Kanal für Nicht-RGB-Daten) werden per Ausgleichung nach kleinsten Quadraten aus Zellen geschätzt, die mehrere Bilder sehen. Zellen, die kein Bild sieht, erhalten Alpha 0 und erscheinen in der Verdeckungsmaske. Kanalanzahl und Datentyp der Bilder bleiben erhalten (RGB, 16-Bit-panchromatisch, thermal). Die Verarbeitung läuft kachelweise mit begrenztem Speicher; Fortschritt und Abbruch je Kachel.</translation>
        </message>
        <message>
            <source>Height step between two search planes, metres; empty or 0 = the resolution.</source>
            <translation type="obsolete">Höhenschritt zwischen zwei Suchebenen, Meter; leer oder 0 = die Auflösung.</translation>
        </message>
        <message>
            <source>Number of aggregation directions of semi-global matching: 8 (faster) or 16 (smoother slanted surfaces).</source>
            <translation type="obsolete">Anzahl der Aggregationsrichtungen des Semi-Global Matching: 8 (schneller) oder 16 (glattere geneigte Flächen).</translation>
        </message>
        <message>
            <source>Imports the orientation of an image block (interior and exterior orientation of every image, sparse points) from COLMAP, Orthority or OpenSfM/ODM files into TruOrtho's orientation JSON, and writes a layer of projection centres and a layer of image footprints. Conventions (camera axes, rotations, pixel origin) are converted at import; see the README, 'Formats and conventions'.</source>
            <translation type="obsolete">Importiert die Orientierung eines Bildverbands (innere und äußere Orientierung jedes Bildes, dünne Punktwolke) aus COLMAP-, Orthority- oder OpenSfM/ODM-Dateien in das Orientierungs-JSON von TruOrtho und schreibt einen Layer der Projektionszentren und einen Layer der Bildabdeckungen. Konventionen (Kameraachsen, Rotationen, Pixelursprung) werden beim Import umgerechnet; siehe README, 'Formats and conventions'.</translation>
        </message>
        <message>
            <source>Keep the measurements as a table layer in the project</source>
            <translation type="obsolete">Messungen als Tabellenlayer im Projekt behalten</translation>
        </message>
        <message>
            <source>Reports the versions of QGIS, GDAL, rasterio, numpy, numba, OpenCV and pyproj that TruOrtho runs with, and writes them to a JSON file. Fails if rasterio is linked to a different GDAL than QGIS.</source>
            <translation type="obsolete">Meldet die Versionen von QGIS, GDAL, rasterio, numpy, numba, OpenCV und pyproj, mit denen TruOrtho läuft, und schreibt sie in eine JSON-Datei. Schlägt fehl, wenn rasterio gegen ein anderes GDAL als QGIS gelinkt ist.</translation>
        </message>
        <message>
            <source>Projection centres as PointZ with name, camera, x, y, z, omega, phi, kappa (degrees).</source>
            <translation type="obsolete">Projektionszentren als PointZ mit name, camera, x, y, z, omega, phi, kappa (Grad).</translation>
        </message>
        <message>
            <source>HTML report (and a JSON file of the same name): sigma0, image RMS, per-image residuals, GCP and check point tables, residual vector plots, tie-point multiplicity histogram, block overview.</source>
            <translation type="obsolete">HTML-Bericht (und eine gleichnamige JSON-Datei): Sigma0, Bild-RMS, Residuen je Bild, Tabellen der Pass- und Kontrollpunkte, Residuenvektor-Grafiken, Histogramm der Vielfachheit der Verknüpfungspunkte, Verbandsübersicht.</translation>
        </message>
        <message>
            <source>Projection centres (PointZ) with omega, phi, kappa.</source>
            <translation type="obsolete">Projektionszentren (PointZ) mit omega, phi, kappa.</translation>
        </message>
        <message>
            <source>Folder of the products (created when missing; existing products are replaced).</source>
            <translation type="obsolete">Ordner der Produkte (wird angelegt, falls er fehlt; vorhandene Produkte werden ersetzt).</translation>
        </message>
        <message>
            <source>Exports a DSM as a point cloud, one point per valid cell centre, with colours from an orthoimage and per-point confidence from a confidence raster: LAS 1.4 or LAZ (point format 7, CRS as WKT, extra dimensions 'confidence' and 'system' (the reference system), a TruOrtho VLR describing the reference systems), readable by PDAL, laspy, LAStools and CloudCompare. An Entwine Point Tile (EPT) dataset is written beside it: QGIS builds without PDAL (as Debian's QGIS 3.22) open it as a point cloud layer (Layer &gt; Add Layer &gt; Point Cloud, choose ept.json).</source>
            <translation type="obsolete">Exportiert ein DOM als Punktwolke, ein Punkt je gültigem Zellmittelpunkt, mit Farben aus einem Orthobild und Konfidenz je Punkt aus einem Konfidenzraster: LAS 1.4 oder LAZ (Punktformat 7, KBS als WKT, Zusatzdimensionen 'confidence' und 'system' (das Referenzsystem), ein TruOrtho-VLR, der die Referenzsysteme beschreibt), lesbar mit PDAL, laspy, LAStools und CloudCompare. Daneben wird ein Entwine-Point-Tile-Datensatz (EPT) geschrieben: QGIS-Builds ohne PDAL (wie das QGIS 3.22 von Debian) öffnen ihn als Punktwolken-Layer (Layer &gt; Layer hinzufügen &gt; Punktwolke, ept.json wählen).</translation>
        </message>
        <message>
            <source>GeoTIFF with the images' bands and data type plus an alpha band, tiled, with overviews, Cloud-Optimized GeoTIFF layout.</source>
            <translation type="obsolete">GeoTIFF mit den Kanälen und dem Datentyp der Bilder plus einem Alphakanal, gekachelt, mit Übersichten, im Cloud-Optimized-GeoTIFF-Layout.</translation>
        </message>
    </context>
</TS>
